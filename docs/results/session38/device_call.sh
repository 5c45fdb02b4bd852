#!/usr/bin/env bash
# Session 38, one device call (H200): the fit's timing with the host walks split over the cores
# (50a53c5, and then its chunks of 4,096) against the build before it (12d97b6), interleaved, two
# rounds each; the walks' tests on the device machine's 16 cores. Text results only.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#          mkdir -p .device-pkgs/extra && cp build/tests/test_engine .device-pkgs/extra/ &&
#          cp <12d97b6's build>/apps/voxbreast .device-pkgs/extra/voxbreast_before
#   run:   bash docs/results/session38/device_call.sh   (carry [".device-pkgs"])
set -uo pipefail
cd "$(dirname "$0")/../../.."
root=$PWD
# the bundle unpacked once: everything below runs inside gpu_run.sh's environment
[[ "${1:-}" == inner ]] || exec bash scripts/gpu_run.sh run bash "$root/docs/results/session38/device_call.sh" inner
work=$(mktemp -d)
nproc >"$OUT/host_cores.txt"
"$root/.device-pkgs/extra/test_engine" --gtest_filter='TimeStep.*:ParallelChunks.*' 2>&1 |
  grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' >"$OUT/test_engine_walks.txt"
tail -n 2 "$OUT/test_engine_walks.txt"
bin_before=$root/.device-pkgs/extra/voxbreast_before
bin_after=$(command -v voxbreast)
for round in 1 2; do
  for build in before after; do
    OUT=$work/$build$round VOXBREAST_BIN=$([[ $build == before ]] && echo "$bin_before" || echo "$bin_after") timeout 150 bash scripts/gpu_fit.sh >"$work/$build$round.log" 2>&1
    cp "$work/$build$round/fit/timing.txt" "$OUT/fit_timing_${build}_round${round}_h200.txt"
    echo "== $build, round $round"
    grep -E '^== |real|jacobian_timing|wall_time' "$OUT/fit_timing_${build}_round${round}_h200.txt"
  done
done
