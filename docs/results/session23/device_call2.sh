#!/usr/bin/env bash
# Session 23, device call 2 (H200), the build of call 1 (attempt 26's variants selectable):
# (a) attempt 26's PTX: instructions and registers of heun_predict for a 64k cube (the launched
#     step, which takes the short loop), old / new / shift;
# (b) the step list for hyperelastic relaxation between 76k and 147k (change 24: −1 to −2% at
#     76k, gains from 147k): the phantom at 90k, 110k, 130k, neo-Hookean and Ogden, list on and
#     off, two rounds interleaved.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
for v in old new shift; do
  case $v in old) opt=-DVB_EXP_OLD=1;; new) opt=;; shift) opt=-DVB_EXP_SHIFT=1;; esac
  VOXBREAST_CL_OPTIONS="$opt -cl-nv-verbose" VOXBREAST_DUMP_KERNELS=/tmp/ptx_$v timeout 60 $G voxbreast bench --quick --no-study --sizes 40 --out /tmp/p >/dev/null 2>&1
  for b in /tmp/ptx_$v/*.bin; do
    n=$(awk '/\.entry heun_predict\(/,/^}/' $b | grep -cE '^\s+[a-z@]')
    [ "$n" -gt 0 ] || continue
    echo "$v: heun_predict PTX instructions $n, of them f32 arithmetic $(awk '/\.entry heun_predict\(/,/^}/' $b | grep -cE '^\s+(@%p[0-9]+ )?(add|sub|mul|fma|neg|max|min|rsqrt|sqrt|rcp|div|selp|abs)\.(rn\.|approx\.|ftz\.)*(ftz\.)?f32'), loads $(awk '/\.entry heun_predict\(/,/^}/' $b | grep -cE '^\s+(@%p[0-9]+ )?ld\.global')"
    grep -A2 "heun_predict" ${b%.bin}.log | grep -iE "registers|spill" | head -2
  done
done 2>&1 | tee $o/attempt26_ptx.txt
run() {  # label, env..., then bench arguments after --
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  echo "== $label"; env "${envs[@]}" timeout 160 $G voxbreast bench --quick --no-study "$@" --out /tmp/t 2>&1 | grep -E "^(breast|block)"
  { echo "# $label"; cat /tmp/t/throughput.csv; } >> $o/list_hyper_relax.csv
}
{
for r in 1 2; do
for L in 1 0; do
run "r$r list=$L hyperelastic relaxation" VOXBREAST_STEP_LIST=$L -- --breast-elements 90000 110000 130000 --laws neo-hookean ogden --integrators relaxation
done
done
} 2>&1 | tee $o/list_hyper_relax.txt
