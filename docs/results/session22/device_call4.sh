#!/usr/bin/env bash
# Session 22, device call 4 (H200): the step list below its limit (65,536) for the integrators it
# serves there: relaxation and symplectic Euler (every law) and Heun (linear, launched from
# 45,056), the phantom resampled to 30k-65k, list on and off, two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 140 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/list_below_limit.csv
}
{
for r in 1 2; do
for L in 1 0; do
run "r$r list=$L relaxation, euler" VOXBREAST_STEP_LIST=$L -- --breast-elements 30000 45000 55000 65000 --laws linear neo-hookean ogden --integrators relaxation symplectic_euler
run "r$r list=$L heun linear" VOXBREAST_STEP_LIST=$L -- --breast-elements 50000 60000
done
done
} 2>&1 | tee $o/list_below_limit.txt
