#!/usr/bin/env bash
# Session 30, device call 2 (H200): why main's march (change 31 as built: 10% slower than the gather
# at 1.5M, call 1) is not the prototype's (+11%): the same build with the class coefficients per
# centre (VB_MARCH_COEF, the prototype's MIN), without the general loop's fallback (timing only),
# and pieces of 2 and 4 centres; quick rows at 512k and 1.5M against the gather.
set -u
o=$OUT
Q="bench --device gpu --quick --no-study --sizes 80 115"
r() { echo "== $1"; shift; env "$@" bash scripts/gpu_run.sh run voxbreast $Q --out /tmp/b 2>&1 | grep -E "^block"; }
{
r gather VOXBREAST_MARCH=0
r march VOXBREAST_MARCH=1
r coef VOXBREAST_CL_OPTIONS=-DVB_MARCH_COEF=1
r no-fallback VOXBREAST_CL_OPTIONS=-DVB_MARCH_NO_FALLBACK=1
r "coef, no fallback" "VOXBREAST_CL_OPTIONS=-DVB_MARCH_COEF=1 -DVB_MARCH_NO_FALLBACK=1"
r "tz 2" VOXBREAST_MARCH_TZ=2
r "tz 4" VOXBREAST_MARCH_TZ=4
r "coef, tz 2" VOXBREAST_MARCH_TZ=2 VOXBREAST_CL_OPTIONS=-DVB_MARCH_COEF=1
r "coef, tz 4" VOXBREAST_MARCH_TZ=4 VOXBREAST_CL_OPTIONS=-DVB_MARCH_COEF=1
r gather VOXBREAST_MARCH=0
r march VOXBREAST_MARCH=1
# (This part printed no registers: 40³ = 64,000 elements is below the march's rule of 131,072,
# so the march kernels were not built; PERF_NOTES.md cites call 1's registers.)
mkdir -p /tmp/dump
for opt in "-DVB_MARCH_COEF=1" "-DVB_MARCH_NO_FALLBACK=1"; do
  rm -f /tmp/dump/*
  VOXBREAST_DUMP_KERNELS=/tmp/dump VOXBREAST_CL_OPTIONS="-cl-nv-verbose $opt" timeout 120 bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 40 --out /tmp/b >/dev/null 2>&1
  echo "== registers $opt"; grep -A4 "entry function 'heun_.*march" /tmp/dump/*.log | grep -E "entry|Used|spill"
done
} 2>&1 | tee $o/variants_call2_h200.txt
