#!/usr/bin/env bash
# Haptic rate on a GPU (issue 9, docs/BENCHMARKS.md "Haptic rate"), in one device call (~2 min):
# the bench's probe-pressing blocks (10k, 40k, 160k elements; force output at 1 kHz) and the
# voxbreast haptic sample with its force log.
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/gpu_haptic.sh          (run tool, carry [".device-pkgs"]; writes $OUT/haptic)
#   here:   python3 scripts/haptic_table.py FETCHED/haptic/bench.json   # rows for BENCHMARKS.md
# Extra bench options go in $HAPTIC_ARGS, e.g. HAPTIC_ARGS="--haptic-seconds 10".
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/haptic
mkdir -p "$out"
bash scripts/gpu_run.sh run voxbreast info >"$out/device.txt" 2>&1 || true
# shellcheck disable=SC2086
bash scripts/gpu_run.sh run voxbreast bench --device gpu --haptic --no-study --haptic-elements 10000 40000 160000 \
  --haptic-seconds 5 --out "$out" ${HAPTIC_ARGS:-} 2>&1 | tee "$out/bench.log"
# The sample: 10k elements, an 8 mm press and release over 3 s.
bash scripts/gpu_run.sh run voxbreast haptic data-samples/haptic/block.toml --device gpu \
  --trajectory data-samples/haptic/press.csv --rate-hz 1000 --out "$out/sample" 2>&1 | tee "$out/sample.log"
if command -v python3 >/dev/null; then python3 scripts/haptic_table.py "$out/bench.json"; fi
