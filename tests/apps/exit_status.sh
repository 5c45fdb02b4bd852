#!/usr/bin/env bash
# Exit statuses of voxbreast simulate and probe: 0 converged (or a fixed run as asked), 3 not
# converged (outputs written, summary.json says why), 4 unstable (nothing written, the cause named),
# 1 a scene that cannot settle or cannot run.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/exit_status.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"

scene() {  # the shared block (lib.sh), relaxed in double; extra lines appended
  block_scene
  printf '[solver]\nintegrator = "relaxation"\nprecision = "double"\n'
}
run() {  # name, scene text: runs simulate, sets rc
  printf '%s\n' "$2" >"$work/$1.toml"
  "$bin" simulate "$work/$1.toml" --out "$work/$1" --quiet >"$work/$1.out" 2>"$work/$1.err"
  rc=$?
}
summary() {  # name, python expression over the summary s
  python3 -c "import json, sys; s = json.load(open('$work/$1/summary.json')); sys.exit(0 if ($2) else 1)"
}

run converged "$(scene)"
if [[ $rc -eq 0 ]] && summary converged 's["converged"] and s["unconverged_reason"] is None'; then
  pass "converged: exit 0"
else fail "converged (rc $rc)"; cat "$work/converged.err"; fi

run max_steps "$(scene; printf '[stop]\nmax_steps = 40\n')"
if [[ $rc -eq 3 ]] && [[ -s "$work/max_steps/result.h5" ]] \
   && summary max_steps 'not s["converged"] and "stop.max_steps" in s["unconverged_reason"] and s["unconverged_reason"] in s["warnings"]' \
   && grep -q "^voxbreast: warning: stopped at stop.max_steps after 40 steps before equilibrium" "$work/max_steps.err" \
   && grep -q "not converged.*exit status 3" "$work/max_steps.err"; then
  pass "stopped at max_steps: exit 3, outputs written, converged false with the reason"
else fail "max_steps (rc $rc)"; cat "$work/max_steps.err"; fi

run fixed "$(scene; printf '[stop]\nmax_steps = 40\nequilibrium = 0\n')"
if [[ $rc -eq 0 ]] && summary fixed 'not s["converged"] and s["unconverged_reason"] is None and s["steps"] == 40'; then
  pass "a fixed number of steps as asked (equilibrium = 0): exit 0"
else fail "fixed steps (rc $rc)"; cat "$work/fixed.err"; fi

run trivial "$(scene | sed 's/^E = 3000.0/E = 3.0e9/')"
if [[ $rc -eq 3 ]] && summary trivial 'not s["converged"] and "trivially" in s["unconverged_reason"]'; then
  pass "equilibrium met trivially: exit 3"
else fail "trivial equilibrium (rc $rc)"; cat "$work/trivial.err"; fi

expect_refusal() {  # name, rc, expected text, scene text
  run "$1" "$4"
  if [[ $rc -eq $2 && $(wc -l <"$work/$1.err") -eq 1 ]] && grep -q "^voxbreast: error:.*$3" "$work/$1.err" \
     && [[ ! -e "$work/$1" ]]; then
    pass "$1: exit $2: $(cat "$work/$1.err")"
  else fail "$1 (rc $rc, expected $2 and '$3')"; cat "$work/$1.err"; fi
}
expect_refusal too_large_dt 4 "try solver.dt" \
  "$(scene | sed 's/^integrator = .*/integrator = "symplectic_euler"\ndt = 0.01/')"
expect_refusal too_soft 4 "too soft to carry its own weight" "$(scene | sed 's/^E = 3000.0/E = 1e-30/')"
if ! grep -q "solver.dt" "$work/too_soft.err"; then pass "too soft: no step blamed"; else fail "too soft blames dt"; fi
expect_refusal no_anchor 1 "joined to no held element: under gravity it falls freely" \
  "$(scene | sed '/^\[anchor.base\]/,+3d')"
expect_refusal mooney_rivlin_not_stable 1 "materials.soft.c01.*not stable" \
  "$(scene | sed 's/^E = 3000.0/law = "mooney-rivlin"\nc10 = 1000.0\nc01 = -999.999/')"
expect_refusal stop_time_below_a_step 1 "stop.time.*shorter than one step" \
  "$(scene; printf '[stop]\ntime = 1e-300\n')"
finish
