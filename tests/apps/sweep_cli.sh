#!/usr/bin/env bash
# End-to-end checks of `voxbreast sweep` on a tiny block scene (docs/SWEEP.md):
#   resume  — a sweep stopped (--stop-after) or killed (kill -9) midway and restarted writes the
#             same metrics.csv, byte for byte, as an uninterrupted one; two workers on one device
#             too; bad keys, another grid in the same folder, failing cases
#   mpi     — `mpirun -n 2` matches the serial sweep, also when an MPI sweep is stopped midway and
#             finished by a serial run
#   sample  — the bundled sample sweep (data-samples/phantom/sweep.sh): all cases converge, the
#             tumour moves less in stiffer tissue, plots are drawn
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/sweep_cli.sh . resume
set -uo pipefail
root=${1:?source dir}
mode=${2:?resume, mpi or sample}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"

cat >"$work/block.toml" <<'TOML'
# a 5×5×5 block settling on a held base
[model]
spacing = 0.002
[[model.shape]]
kind = "box"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
label = "soft"
[materials.soft]
E = 3000.0
[gravity]
vector = [0.0, 0.0, -9.81]
[anchor.base]
kind = "halfspace"
point = [0.0, 0.0, 0.002]
normal = [0.0, 0.0, -1.0]
[[track]]
name = "top"
point = [0.005, 0.005, 0.01]
[stop]
max_steps = 3000
TOML
grid=(--vary materials.soft.E=2000:4000:3 --vary gravity.vector.3=-9.81,-4.9)
sweep() { "$bin" sweep "$work/block.toml" "${grid[@]}" --no-plots "$@"; }
same_metrics() {  # name, folder: metrics.csv equals the serial one, byte for byte
  if cmp -s "$work/serial/metrics.csv" "$2/metrics.csv"; then pass "$1"; else fail "$1"; diff "$work/serial/metrics.csv" "$2/metrics.csv" | head -5; fi
}

if ! sweep --out "$work/serial" -q >"$work/serial.txt" 2>&1 || [[ $(grep -c ',ok,' "$work/serial/metrics.csv") -ne 6 ]]; then
  fail "serial sweep"; cat "$work/serial.txt"; finish; exit 1
fi
pass "serial sweep: 6 cases ok"

case $mode in
resume)
  # Stopped after 2 cases (exit 3: not finished), then restarted.
  sweep --out "$work/stopped" --stop-after 2 -q >"$work/stopped.txt" 2>&1
  rc=$?
  finished=$(ls "$work/stopped/cases" | grep -c '^[0-9]*$')
  if [[ $rc -eq 3 && $finished -eq 2 ]] && grep -q ',pending,' "$work/stopped/metrics.csv"; then
    pass "--stop-after 2: exit 3, 2 cases finished, the rest pending"
  else fail "--stop-after 2 (rc $rc, $finished finished)"; cat "$work/stopped.txt"; fi
  sweep --out "$work/stopped" >"$work/restarted.txt" 2>&1
  grep -q "2 cases were finished before this run" "$work/restarted.txt" && [[ $(grep -c '^case ' "$work/restarted.txt") -eq 4 ]] \
    && pass "restart skips the 2 finished cases and runs the other 4" || { fail "restart after --stop-after"; cat "$work/restarted.txt"; }
  same_metrics "stopped + restarted sweep: same metrics.csv" "$work/stopped"

  # Killed (SIGKILL) while running, then restarted.
  "$bin" sweep "$work/block.toml" "${grid[@]}" --no-plots --out "$work/killed" -q >"$work/killed.txt" 2>&1 &
  pid=$!  # voxbreast itself, not a subshell
  for _ in $(seq 1 3000); do [[ -e "$work/killed/cases/0001/case.json" ]] && break; sleep 0.01; done
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  finished=$(ls "$work/killed/cases" 2>/dev/null | grep -c '^[0-9]*$')
  if [[ $finished -ge 1 && $finished -lt 6 ]]; then pass "kill -9 after $finished of 6 cases"; else fail "kill -9 midway ($finished of 6 finished)"; fi
  sweep --out "$work/killed" -q >"$work/killed2.txt" 2>&1 || { fail "restart after kill"; cat "$work/killed2.txt"; }
  same_metrics "killed + restarted sweep: same metrics.csv" "$work/killed"
  leftovers=$(ls -A "$work/killed/cases" | grep '^\.' || true)
  [[ -z $leftovers ]] && pass "the killed run's working folder was removed" || fail "working folders left: $leftovers"

  # Two workers (two OpenCL contexts) on the one CPU device.
  sweep --out "$work/two" --devices cpu,cpu -q >"$work/two.txt" 2>&1 || { fail "--devices cpu,cpu"; cat "$work/two.txt"; }
  same_metrics "--devices cpu,cpu: same metrics.csv" "$work/two"
  [[ $(cut -d, -f4 "$work/two/timing.csv" | sort -u | grep -c '^[01]$') -ge 1 ]] && pass "timing.csv names the worker of each case" || fail "timing.csv workers"

  # Another grid into the same folder is refused; so is a typo; each with one error line.
  "$bin" sweep "$work/block.toml" --vary materials.soft.E=2000:4000:4 --out "$work/serial" -q >/dev/null 2>"$work/grid.err"
  rc=$?
  [[ $rc -ne 0 ]] && grep -q "^voxbreast: error:.*another sweep" "$work/grid.err" && pass "another grid in the same folder: $(cat "$work/grid.err")" || { fail "another grid (rc $rc)"; cat "$work/grid.err"; }
  "$bin" sweep "$work/block.toml" --vary materials.soft.Ee=1,2 --out "$work/typo" -q >/dev/null 2>"$work/typo.err"
  rc=$?
  [[ $rc -ne 0 && $(wc -l <"$work/typo.err") -eq 1 && ! -e "$work/typo" ]] && grep -q "did you mean 'E'" "$work/typo.err" \
    && pass "typo in a key: $(cat "$work/typo.err")" || { fail "typo (rc $rc)"; cat "$work/typo.err"; }

  # A case that blows up is recorded as failed, with its error; the others run; exit 0.
  "$bin" sweep "$work/block.toml" --vary +solver.integrator=symplectic_euler --vary +solver.dt=1e-4,0.01 --out "$work/unstable" --no-plots -q \
    >"$work/unstable.txt" 2>&1
  rc=$?
  if [[ $rc -eq 0 ]] && grep -q '^0001,symplectic_euler,1e-4,ok,' "$work/unstable/metrics.csv" \
     && grep -q '^0002,symplectic_euler,0.01,failed,.*unstable' "$work/unstable/metrics.csv"; then
    pass "unstable case recorded as failed with its error"
  else fail "unstable case (rc $rc)"; cat "$work/unstable.txt" "$work/unstable/metrics.csv"; fi

  # Plots, when Debian's Python has matplotlib.
  if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
    /usr/bin/python3 "$root/scripts/plot_sweep.py" "$work/serial" >"$work/plots.txt" 2>&1 && [[ -s "$work/serial/plots/overview.png" ]] \
      && [[ -s "$work/serial/plots/tracked.top.displacement_norm_m.png" ]] && pass "plots: $(cat "$work/plots.txt")" || { fail "plots"; cat "$work/plots.txt"; }
  fi
  ;;
mpi)
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # CI runs as root
  mpirun=${MPIEXEC:-mpirun}
  "$mpirun" -n 2 --oversubscribe "$bin" sweep "$work/block.toml" "${grid[@]}" --no-plots --out "$work/mpi" >"$work/mpi.txt" 2>&1 \
    || { fail "mpirun -n 2 sweep"; cat "$work/mpi.txt"; }
  same_metrics "mpirun -n 2: same metrics.csv as the serial sweep" "$work/mpi"
  ranks=$(cut -d, -f3 "$work/mpi/timing.csv" | tail -n +2 | sort -u | tr '\n' ' ')
  [[ $ranks == "0 1 " ]] && pass "cases ran on ranks 0 and 1" || fail "ranks in timing.csv: '$ranks'"
  [[ $(cut -d, -f1,3 "$work/mpi/timing.csv" | grep -c '^000[135],0$') -eq 3 ]] && pass "static partition: case i on rank (i-1) mod 2" || fail "partition"
  # Stopped midway under MPI (one case per rank), finished by a serial run.
  "$mpirun" -n 2 --oversubscribe "$bin" sweep "$work/block.toml" "${grid[@]}" --no-plots --stop-after 1 -q --out "$work/mix" >"$work/mix.txt" 2>&1
  [[ $(ls "$work/mix/cases" | grep -c '^[0-9]*$') -eq 2 ]] && pass "mpirun --stop-after 1: 2 cases" || { fail "mpirun --stop-after"; cat "$work/mix.txt"; }
  sweep --out "$work/mix" -q >"$work/mix2.txt" 2>&1 || { fail "serial finish of an MPI sweep"; cat "$work/mix2.txt"; }
  same_metrics "MPI sweep finished serially: same metrics.csv" "$work/mix"
  ;;
sample)
  start=$(date +%s)
  VOXBREAST_BIN=$bin bash "$root/data-samples/phantom/sweep.sh" "$work/sample" >"$work/sample.txt" 2>&1
  rc=$?
  echo "sample sweep: $(( $(date +%s) - start )) s"
  if [[ $rc -eq 0 ]] && /usr/bin/python3 - "$work/sample" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/metrics.csv")))
assert len(rows) == 6 and all(r["status"] == "ok" and r["converged"] == "true" for r in rows), rows
for posture in ("prone", "supine"):
    d = [float(r["tracked.tumour_1.displacement_norm_m"]) for r in rows if r["gravity.posture"] == posture]
    assert d[0] > d[1] > d[2] > 0, (posture, d)  # stiffer adipose (E up): the tumour moves less
up = {r["gravity.posture"]: float(r["tracked.tumour_1.displacement_m.2"]) for r in rows if r["materials.adipose.E"] == "4000"}
assert up["prone"] < 0 < up["supine"], up  # LPS y is posterior: prone sags anteriorly, supine posteriorly
PY
  then pass "sample sweep: 6 cases converge; tumour displacement falls with adipose E; prone/supine move it opposite ways"
  else fail "sample sweep (rc $rc)"; cat "$work/sample.txt"; fi
  if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
    [[ -s "$work/sample/plots/overview.png" ]] && pass "sample plots drawn" || { fail "sample plots"; cat "$work/sample.txt"; }
  fi
  ;;
device)
  # The device-design sample sweep (docs/POSITIONING.md): stopped after one case, then finished.
  start=$(date +%s)
  VOXBREAST_BIN=$bin bash "$root/data-samples/phantom/sweep_device.sh" "$work/device" --stop-after 1 -q --no-plots >"$work/device1.txt" 2>&1
  rc=$?  # 3: cases left to run
  [[ $rc -eq 3 && $(ls "$work/device/cases" | grep -c '^[0-9]*$') -eq 1 ]] && pass "device sweep stopped after 1 case (exit 3)" \
    || { fail "device sweep --stop-after 1 (rc $rc)"; cat "$work/device1.txt"; }
  VOXBREAST_BIN=$bin bash "$root/data-samples/phantom/sweep_device.sh" "$work/device" >"$work/device.txt" 2>&1
  rc=$?
  echo "device sweep: $(( $(date +%s) - start )) s"
  if [[ $rc -eq 0 ]] && /usr/bin/python3 - "$work/device" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/metrics.csv")))
assert len(rows) == 3 and all(r["status"] == "ok" and r["converged"] == "true" for r in rows), rows
R = [float(r["device.torus.2.major_radius"]) for r in rows]
squeeze = [float(r["immobilisation_device.tori.2.normal_force_sum_n"]) for r in rows]
assert R == sorted(R) and squeeze[0] > squeeze[1] > squeeze[2] > 0.5, squeeze  # tighter ring, harder squeeze
for r in rows:  # same postures with and without the device; the device holds the tumour better
    assert float(r["positioning.reproducibility.with_device.std_m"]) < float(r["positioning.reproducibility.without_device.std_m"]), r
    assert float(r["reference_state.residual_max_m"]) <= 1e-5, r
PY
  then pass "device sweep: 3 cases converge; the tighter front ring squeezes harder; the device cuts the tumour spread in each"
  else fail "device sweep (rc $rc)"; cat "$work/device.txt"; fi
  ;;
*) echo "unknown mode $mode"; exit 2 ;;
esac

finish
