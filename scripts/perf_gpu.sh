#!/usr/bin/env bash
# Issue 7 step-time measurements on a GPU in one device call (~3–4 min on an H200): the volume and
# kernel tests on the GPU first (volume_project and volume_pending rely on a last-work-group count
# across the device; the GPU runs the split force passes), then per-kernel profiles of the 36k rows
# (docs/PERF_NOTES.md) with the defaults, and A/B runs of 36k Ogden + Heun + volume, float (the
# 20k target row) over this branch's switches:
#   VOXBREAST_VOLUME_LAUNCHES=0|1|2  projection left pending for the next kernels | one | two launches
#   VOXBREAST_VOLUME_PAIRS=0         the volume gradient's old four-load chains (1, default: pairs)
#   VOXBREAST_FORCE_SPLIT=1|2|4      work-items per element in Heun's force passes (GPU default 2
#                                    for hyperelastic models up to 262,144 elements)
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/perf_gpu.sh      (run tool, carry [".device-pkgs"]; writes $OUT/perf)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/perf
mkdir -p "$out"
run() { bash scripts/gpu_run.sh run "$@"; }

VOXBREAST_DEVICE=gpu run test_physics --gtest_filter='*VolumeKernels*:VolumeConstraint.*:*KernelForces*:*KernelSteps*:HyperelasticKernels.*' \
  2>&1 | grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure|pending vs' | tee "$out/gpu_tests.txt"
# the split force passes (four work-items per element, any law) against the host
VOXBREAST_DEVICE=gpu VOXBREAST_FORCE_SPLIT=4 run test_physics --gtest_filter='*KernelSteps*:HyperelasticKernels.MatchHost*' \
  2>&1 | grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' | tee "$out/gpu_tests_split4.txt"
bench=(voxbreast bench --device gpu --quick --no-study --profile)
run "${bench[@]}" --sizes 33 --laws linear ogden --volume --out "$out/36k" 2>&1 | tee "$out/36k.txt"
# A/B of the target row: name, then the environment
ab() {
  local name=$1; shift
  echo "== $name: $*" | tee "$out/36k_$name.txt"
  env "$@" bash scripts/gpu_run.sh run "${bench[@]}" --sizes 33 --laws ogden --volume --out "$out/36k_$name" 2>&1 |
    tee -a "$out/36k_$name.txt"
}
ab main_kernels VOXBREAST_VOLUME_LAUNCHES=2 VOXBREAST_VOLUME_PAIRS=0 VOXBREAST_FORCE_SPLIT=1
ab pairs VOXBREAST_VOLUME_LAUNCHES=2 VOXBREAST_FORCE_SPLIT=1
ab pending_nopairs VOXBREAST_VOLUME_LAUNCHES=0 VOXBREAST_VOLUME_PAIRS=0 VOXBREAST_FORCE_SPLIT=1
ab pending VOXBREAST_VOLUME_LAUNCHES=0 VOXBREAST_FORCE_SPLIT=1
ab pending_split2 VOXBREAST_VOLUME_LAUNCHES=0 VOXBREAST_FORCE_SPLIT=2
ab pending_split4 VOXBREAST_VOLUME_LAUNCHES=0 VOXBREAST_FORCE_SPLIT=4
ab one_launch_split2 VOXBREAST_VOLUME_LAUNCHES=1 VOXBREAST_FORCE_SPLIT=2
grep -hE '^== |^block_volume|^block +[0-9]+ elements +ogden' "$out"/36k_*.txt | tee "$out/ab_summary.txt"
# PTX and build logs (registers, spills) of the 36k Ogden + volume program, pending projection
VOXBREAST_VOLUME_LAUNCHES=0 VOXBREAST_DUMP_KERNELS="$out/ptx" VOXBREAST_CL_OPTIONS=-cl-nv-verbose \
  run voxbreast bench --device gpu --quick --no-study --sizes 8 --laws ogden --volume --out "$out/ptx_run" >/dev/null 2>&1
tar -C "$out/.." -czf "$out/../perf.tar.gz" perf
