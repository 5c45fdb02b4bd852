#!/usr/bin/env bash
# Session 26, device call 4 (H200): main's 1.5M cube step against the prototype's stage pair in one
# call (call 3: prototype 163.5-164.8 us per step timed; main's quick rows 178-181 us in session 25).
# Timing-only variants of main by redefined macros (the per-element gravity and global damping
# terms, which the prototype lacks: each divides by the inverse mass), two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
{
for r in 1 2; do
  for v in "" "-DVB_GLOBAL_DAMPING=0" "-DVB_GRAVITY=0 -DVB_GLOBAL_DAMPING=0"; do
    echo "== r$r main [$v]"
    VOXBREAST_CL_OPTIONS="$v" timeout 100 $G voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b 2>&1 | grep -E "steps/s|rror|warning" | head -5
  done
  timeout 100 $G .device-pkgs/proto_tile 115 2000 docs/results/session26/proto_tile.cl "0:0:0:0:256" 2>&1 | grep order | sed -E 's/  +/ /g'
done
} 2>&1 | tee $OUT/main_vs_proto_h200.txt
