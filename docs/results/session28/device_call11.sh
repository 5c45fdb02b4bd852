#!/usr/bin/env bash
# Session 28, device call 11 (H200): the full-length throughput rows (512 MB copy, 2 s batches)
# at 512k, 1.5M and 4.1M after change 30, the rest of the device budget.
set -u
timeout 150 bash scripts/gpu_run.sh run voxbreast bench --device gpu --no-study --sizes 80 115 160 --out $OUT/bench 2>&1 | tee $OUT/throughput_h200.txt
