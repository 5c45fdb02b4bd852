#!/usr/bin/env bash
# The positioning samples on a GPU, in one device call (docs/POSITIONING.md, docs/SWEEP.md): the
# two-ring device sample (unloaded state + reproducibility), the device-design sweep and the
# phantom sweep. Results come back as $OUT/positioning.tar.gz.
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/gpu_positioning.sh        (run tool, carry [".device-pkgs"])
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/positioning
mkdir -p "$out"
run() { bash scripts/gpu_run.sh run "$@"; }
run voxbreast info >"$out/device.txt" 2>&1 || true
{ time run voxbreast simulate data-samples/phantom/scene_device.toml --out "$out/device" --device gpu --quiet; } \
  >"$out/device.log" 2>&1 || echo "device sample failed (see device.log)"
rm -f "$out/device/result.h5"  # large; summary.json, metrics.csv and reproducibility.csv say it all
{ time VOXBREAST_BIN=voxbreast run bash data-samples/phantom/sweep_device.sh "$out/device_sweep" --devices gpu; } \
  >"$out/device_sweep.log" 2>&1 || echo "device sweep failed (see device_sweep.log)"
{ time VOXBREAST_BIN=voxbreast run bash data-samples/phantom/sweep.sh "$out/phantom_sweep" --devices gpu; } \
  >"$out/phantom_sweep.log" 2>&1 || echo "phantom sweep failed (see phantom_sweep.log)"
find "$out" -name '*.h5' -delete
for log in "$out"/*.log; do tail -n 3 "$log"; done
# Few files come back from the device: one archive (unpack with tar -xzf positioning.tar.gz).
tar -C "$out/.." -czf "$out/../positioning.tar.gz" positioning && rm -rf "$out"
