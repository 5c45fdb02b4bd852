#!/usr/bin/env bash
# Issue 7 step-time measurements on a GPU in one device call (~2 min on an H200): the volume and
# kernel tests on the GPU first (volume_project relies on a last-work-group count across the
# device), then per-kernel profiles of the three target rows (docs/PERF_NOTES.md):
# 36k Ogden + Heun + volume, 36k Ogden + Heun, 1.5M linear + Heun, float; and the 36k volume rows
# with the two-launch projection (VOXBREAST_VOLUME_LAUNCHES=2) to compare.
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/perf_gpu.sh      (run tool, carry [".device-pkgs"]; writes $OUT/perf)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/perf
mkdir -p "$out"
run() { bash scripts/gpu_run.sh run "$@"; }

VOXBREAST_DEVICE=gpu run test_physics --gtest_filter='*VolumeKernels*:VolumeConstraint.*:*KernelForces*:*KernelSteps*:HyperelasticKernels.*' \
  2>&1 | grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' | tee "$out/gpu_tests.txt"
bench=(voxbreast bench --device gpu --quick --no-study --profile)
run "${bench[@]}" --sizes 33 --laws linear ogden --volume --out "$out/36k" 2>&1 | tee "$out/36k.txt"
VOXBREAST_VOLUME_LAUNCHES=2 run "${bench[@]}" --sizes 33 --laws linear ogden --volume --out "$out/36k_two_launches" \
  2>&1 | tee "$out/36k_two_launches.txt"
run "${bench[@]}" --sizes 115 --out "$out/1p5m" 2>&1 | tee "$out/1p5m.txt"
# PTX and build logs (registers, spills) of the 36k Ogden + volume program
VOXBREAST_DUMP_KERNELS="$out/ptx" VOXBREAST_CL_OPTIONS=-cl-nv-verbose \
  run voxbreast bench --device gpu --quick --no-study --sizes 8 --laws ogden --volume --out "$out/ptx_run" >/dev/null 2>&1
tar -C "$out/.." -czf "$out/../perf.tar.gz" perf
