#!/usr/bin/env bash
# Session 28, device call 7 (H200): main's own PTX for the 1.5M cube's stepping kernels
# (VOXBREAST_DUMP_KERNELS), to compare instruction by instruction with the prototype's gather;
# quick rows at 512k and 1.5M as this session's baseline.
set -u
o=$OUT
{
VOXBREAST_DUMP_KERNELS=$o/dump VOXBREAST_CL_OPTIONS=-cl-nv-verbose timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 115 --out /tmp/b1 2>&1 | tail -5
ls -la $o/dump | head -20
for i in 1 2; do timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 80 115 --out /tmp/b2 2>&1 | grep -E "cube|block|steps/s" | head -8; done
} 2>&1 | tee $o/main_ptx_h200.txt
