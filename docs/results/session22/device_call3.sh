#!/usr/bin/env bash
# Session 22, device call 3 (H200): the launched Heun step of cubes of 39k-43k ran at 60-62k
# steps/s in call 1 and at 72-73k in call 2 (the one-launch step 69-70k in both). Which is it:
# the default (one-launch up to 45,056) against the launched step, cubes of 36k-47k, five rounds
# interleaved, with the host/device split (--profile) in the first, and rounds 4-5 after a
# minute of 1.5M-element load.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 100 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -vE "^\s*$|bench:|^progress"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/one_launch_rounds.csv
}
{
run "r1 default, profile" X=1 -- --sizes 33 34 35 36 --profile
run "r1 launched, profile" VOXBREAST_PERSISTENT=0 -- --sizes 33 34 35 36 --profile
for r in 2 3; do
run "r$r default" X=1 -- --sizes 33 34 35 36
run "r$r launched" VOXBREAST_PERSISTENT=0 -- --sizes 33 34 35 36
done
echo "== load: 1.5M cube, 3 runs"
for i in 1 2 3; do timeout 100 $G voxbreast bench --quick --no-study --sizes 115 --out /tmp/l 2>&1 | grep -E "^block"; done
for r in 4 5; do
run "r$r default" X=1 -- --sizes 33 34 35 36
run "r$r launched" VOXBREAST_PERSISTENT=0 -- --sizes 33 34 35 36
done
} 2>&1 | tee $o/one_launch_rounds.txt
