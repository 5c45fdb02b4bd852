#!/usr/bin/env bash
# Session 21, device call 3 (H200): (a) where the one-launch step stops paying (Heun, linear):
# phantom resampled to 40k-70k and cubes of 47k-85k, one-launch against launched (with the step
# list for the phantom); (b) the step list for hyperelastic relaxation and Euler at 75k and 150k.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 150 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/study3.csv
}
{
for r in 1 2; do
run "r$r heun one-launch" X=1 -- --breast-elements 40000 50000 60000 70000 --sizes 36 40 44
run "r$r heun launched, list" VOXBREAST_PERSISTENT=0 VOXBREAST_STEP_LIST=1 -- --breast-elements 40000 50000 60000 70000
run "r$r heun launched" VOXBREAST_PERSISTENT=0 -- --sizes 36 40 44
done
run "hyper no list" VOXBREAST_STEP_LIST=0 -- --breast-elements 75000 150000 --laws neo-hookean ogden --integrators relaxation symplectic_euler
run "hyper list" VOXBREAST_STEP_LIST=1 -- --breast-elements 75000 150000 --laws neo-hookean ogden --integrators relaxation symplectic_euler
} 2>&1 | tee $o/study3.txt
