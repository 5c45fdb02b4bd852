#!/usr/bin/env bash
# Session 29, device call 4 (H200): the full speed/accuracy study and throughput series at
# d9891ff (change 30 in; attempt 39 measured and not kept), scripts/bench_gpu.sh; only its archive
# comes back (the device tool returns 8 files).
set -u
real_out=$OUT
export OUT=$(mktemp -d)
BENCH_TIMEOUT=470 bash scripts/bench_gpu.sh
cp $OUT/bench.tar.gz $real_out/
tail -5 $OUT/bench/bench.log
