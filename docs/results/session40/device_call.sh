#!/usr/bin/env bash
# Prepared in session 40 and not run (no device machine could be started in ten calls): issue 7's
# GPU target rows at this commit (the 1.5M cube with its
# gather floor and the copy bandwidth; the 36k breast, two-term Ogden + Heun + volume), then
# test_physics on the GPU (the lanes kernels changed this session are CPU-only: their tests skip
# there; the rest checks the build). Text results only.
#   here:  cmake --build build && bash scripts/gpu_run.sh prepare
#   run:   bash docs/results/session40/device_call.sh   (carry [".device-pkgs"])
set -u
cd "$(dirname "$0")/../../.."
G="bash scripts/gpu_run.sh run"
export VOXBREAST_DEVICE=gpu
$G voxbreast info 2>&1 | head -n 20 >"$OUT/info.txt"
for round in 1 2; do
  timeout 120 $G voxbreast bench --device gpu --quick --no-study --sizes 33 115 --out "$OUT/cube$round" \
    >"$OUT/cube$round.log" 2>&1
  timeout 120 $G voxbreast bench --device gpu --quick --no-study --breast --volume --laws ogden --sizes 33 \
    --out "$OUT/breast$round" >"$OUT/breast$round.log" 2>&1
  grep -E "copy|steps/s|floor" "$OUT/cube$round.log" "$OUT/breast$round.log"
done
s=$(date +%s)
timeout 330 $G test_physics --gtest_brief=1 >"$OUT/test_physics_h200.txt" 2>&1
echo "test_physics rc=$? in $(( $(date +%s) - s )) s"
grep -E "PASSED|FAILED|tests ran|SKIPPED" "$OUT/test_physics_h200.txt" | tail -n 12
