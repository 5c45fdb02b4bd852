#!/usr/bin/env bash
# Session 25, device call 12 (H200): the throughput series of scripts/bench_gpu.sh (cubes 10k-4.1M,
# the phantom at ~1.5M) at the commit of change 28, without the study (its trajectories are
# bit-identical), with the SM clock and power every 250 ms.
set -u
o=$OUT/tp
mkdir -p $o
nvidia-smi --query-gpu=timestamp,clocks.sm,power.draw,clocks_throttle_reasons.active --format=csv -lms 250 > $o/clocks.csv 2>&1 &
smi=$!
timeout 400 bash scripts/gpu_run.sh run voxbreast bench --device gpu --no-study --out $o --phantom data-samples/phantom/scene.toml \
  --sizes 22 33 50 80 115 160 --breast-large 2>&1 | tee $o/bench.log | grep -E "^(breast|block)|copy"
kill $smi
