#!/usr/bin/env bash
# Session 31, device call 3 (H200): the full study and the throughput series with the gather
# floor (scripts/bench_gpu.sh), at the commit the bundle was built from.
set -u
BENCH_TIMEOUT=500 bash scripts/bench_gpu.sh
