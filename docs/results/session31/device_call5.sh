#!/usr/bin/env bash
# Session 31, device call 5 (H200), timing only: the step with the connection dashpots compiled
# out (VOXBREAST_CL_OPTIONS=-DVB_DASHPOT=0 overrides the scene's ζ = 0.1: the bench has no knob for
# it), against the step as the bench runs it, quick rows at 512k and 1.5M, alternating. What a
# spring scene with global damping only (solver.dashpot_ratio = 0) would reach against the copy.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 80 115 --out /tmp/b"
{
for i in 1 2; do
  echo "== dashpots (the bench's cube)"; bash scripts/gpu_run.sh run voxbreast $Q 2>&1 | grep -E "^block|gather floor|copy bandwidth"
  echo "== no dashpots (-DVB_DASHPOT=0)"; VOXBREAST_CL_OPTIONS=-DVB_DASHPOT=0 bash scripts/gpu_run.sh run voxbreast $Q 2>&1 | grep -E "^block|gather floor|copy bandwidth|rror"
done
} 2>&1 | tee $o/no_dashpot_call5_h200.txt
