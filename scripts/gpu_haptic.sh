#!/usr/bin/env bash
# Haptic rate on a GPU (docs/BENCHMARKS.md "Haptic rate"), in one device call (~2 min):
# the bench's probe-pressing blocks (10k, 40k, 160k elements; force output at 1 kHz) and the
# voxbreast haptic sample with its force log.
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/gpu_haptic.sh          (run tool, carry [".device-pkgs"]; writes $OUT/haptic)
#   here:   tar -xzf FETCHED/haptic.tar.gz && python3 scripts/haptic_table.py haptic/bench.json   # rows for BENCHMARKS.md
#           /usr/bin/python3 scripts/plot_force_feedback.py haptic haptic/sample/haptic.csv docs/img/haptic_press_h100_DATE_COMMIT.png
# Extra bench options go in $HAPTIC_ARGS, e.g. HAPTIC_ARGS="--haptic-seconds 10".
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/haptic
mkdir -p "$out"
bash scripts/gpu_run.sh run voxbreast info >"$out/device.txt" 2>&1 || true
# shellcheck disable=SC2086
bash scripts/gpu_run.sh run voxbreast bench --device gpu --haptic --no-study --haptic-elements 10000 40000 160000 \
  --haptic-seconds 5 --out "$out" ${HAPTIC_ARGS:-} 2>&1 | tee "$out/bench.log" || echo "bench failed (see bench.log)"
# The sample: 10k elements, a 3 mm press and release over 3 s (vertex contact, then triangles).
bash scripts/gpu_run.sh run voxbreast haptic data-samples/haptic/block.toml --device gpu \
  --trajectory data-samples/haptic/press.csv --rate-hz 1000 --out "$out/sample" 2>&1 | tee "$out/sample.log" ||
  echo "haptic sample failed (see sample.log)"
# The same press in triangle contact (PROBING.md: stiffer by the sagitta at this spacing).
sed 's/^radius = 0.005$/radius = 0.005\ncontact_surface = "triangles"/' data-samples/haptic/block.toml >"$out/block_triangles.toml"
bash scripts/gpu_run.sh run voxbreast haptic "$out/block_triangles.toml" --device gpu \
  --trajectory data-samples/haptic/press.csv --rate-hz 1000 --out "$out/sample_triangles" 2>&1 | tee "$out/sample_triangles.log" ||
  echo "haptic sample (triangles) failed (see sample_triangles.log)"
if command -v python3 >/dev/null; then python3 scripts/haptic_table.py "$out/bench.json" || true; fi
# Few files come back from the device: one archive as well (unpack with tar -xzf haptic.tar.gz).
tar -C "$out/.." -czf "$out/../haptic.tar.gz" haptic
