#!/usr/bin/env bash
# End-to-end checks of `voxbreast fit` (docs/FIT.md) on a 6 mm phantom (6,505 elements) with one
# DCIS tumour (16.4 kPa), the observation made by the forward model itself (the paper's protocol):
#   accuracy — Gauss-Newton recovers the tumour modulus within 10% and 99% of the elements move
#              within 1 mm of the truth; also with 0.5 mm noise (displacements only), with the
#              neo-Hookean forward model, and with the per-region bisection; bad input fails
#   resume   — a fit stopped (--stop-after) or killed (kill -9) and restarted gives the same
#              history and moduli as an uninterrupted one; a killed batch resumes and writes the
#              same metrics.csv as an uninterrupted batch
#   mpi      — a 2-rank `mpirun` batch writes the same metrics.csv as the serial batch
#   labels   — the observation is a label map of the observed posture (surface distances): from
#              wrong moduli the fit moves adipose and fibroglandular tissue towards the truth and
#              reduces the surface distance and the displacement error
#   surface  — the observation is surface meshes (STL) of the observed posture's body and tumour:
#              exact point-to-mesh distances; from wrong moduli the fit gets closer to the truth
#              than from a label map (no staircase); bad STL files fail naming the file
#   reference — the scene has [reference_state]: a fit solving from the unloaded reference state
#              recovers the moduli of an observation simulated with it better than one without,
#              and resumes exactly
#   VOXBREAST_BIN=build/apps/voxbreast VOXBREAST_DEVICE=cpu bash tests/apps/fit_cli.sh . accuracy
set -uo pipefail
root=${1:?source dir}
mode=${2:?accuracy, resume, mpi, labels, surface or reference}
bin=${VOXBREAST_BIN:?path to voxbreast}
py=$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)
source "$(dirname "$0")/lib.sh"
json() { "$py" -c "import json,math,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$1" "$2"; }
check() {  # name, python condition on the summary d
  if [[ $("$py" -c "import json,math,sys; d=json.load(open(sys.argv[1])); print(bool($3))" "$2" 2>&1) == True ]]; then pass "$1"
  else fail "$1"; head -c 1500 "$2"; fi
}

"$bin" phantom --out "$work/ph" --spacing 6 --tumour dcis,10,-25,5,9 >/dev/null || { fail "phantom"; exit 1; }
scene() {  # name, tumour law block, observation file, extra [fit] lines
  cat >"$work/ph/$1.toml" <<TOML
$(cat "$root/data-samples/phantom/fit_model.toml")
$2
$(cat "$root/data-samples/phantom/fit_solver.inc")
[fit]
from_posture = "supine"
dvf = "$3"
tissues = ["adipose", "fibroglandular", "tumour"]
$4
TOML
}
# The label-map and surface fits start from wrong moduli (their scene's material table): 1.8, 11
# and 6 kPa against the truth's 3.25, 6 and 16.4.
wrong='[materials.adipose]
E = 1800.0
[materials.fibroglandular]
E = 11000.0
[materials.tumour]
E = 6000.0'
label_scene() {  # the deformed truth's label map and the scene ph/lab.toml that observes it
  "$bin" fit "$work/ph/truth.toml" --make-observed-labels "$work/ph/obs_labels.nii.gz" --labels-subdivide 6 >/dev/null \
    || fail "--make-observed-labels"
  scene lab "$wrong" truth.nii.gz 'initial = "materials"'
  sed -i 's/^dvf = .*/observed_labels = "obs_labels.nii.gz"/' "$work/ph/lab.toml"
}
linear='[materials.tumour]
E = 16400.0'
scene truth "$linear" truth.nii.gz ""
"$bin" fit "$work/ph/truth.toml" --make-observation "$work/ph/truth.nii.gz" >/dev/null || fail "--make-observation"

case $mode in
accuracy)
  "$bin" fit "$work/ph/truth.toml" --out "$work/gn" --truth "$work/ph/truth.nii.gz" --no-plots -q >"$work/gn.txt" 2>&1 \
    || { fail "fit"; cat "$work/gn.txt"; }
  s="$work/gn/summary.json"
  echo "     tumour $(json "$s" "round(d['modulus_pa']['tumour']['fitted_E_pa'])") Pa (truth 16400), adipose $(json "$s" "round(d['modulus_pa']['adipose']['fitted_E_pa'])") (3250), fibroglandular $(json "$s" "round(d['modulus_pa']['fibroglandular']['fitted_E_pa'])") (6000); $(json "$s" "d['forward_solves']") forward solves"
  check "Gauss-Newton: tumour modulus within 10% of 16.4 kPa" "$s" "abs(d['modulus_pa']['tumour']['fitted_E_pa'] / 16400 - 1) <= 0.10"
  check "Gauss-Newton: adipose and fibroglandular within 2%" "$s" \
    "abs(d['modulus_pa']['adipose']['fitted_E_pa'] / 3250 - 1) <= 0.02 and abs(d['modulus_pa']['fibroglandular']['fitted_E_pa'] / 6000 - 1) <= 0.02"
  check "Gauss-Newton: >= 99% of elements within 1 mm of the truth, RMS below 0.01 mm" "$s" \
    "d['truth']['within_1mm'] >= 0.99 and d['truth']['rms_mm'] < 0.01 and d['final']['rms_mm'] < d['initial']['rms_mm']"
  for f in elasticity.nii.gz displacement.nii.gz residual_mm.nii.gz history.csv regions.csv checkpoint.json; do
    [[ -s "$work/gn/$f" ]] || fail "output $f"
  done
  [[ $(tail -n +2 "$work/gn/history.csv" | wc -l) -ge 2 ]] && pass "history.csv has a row per iteration" || fail "history.csv"

  "$bin" fit "$work/ph/truth.toml" --make-observation "$work/ph/noisy.nii.gz" --noise-mm 0.5 --seed 3 >/dev/null
  scene noisy "$linear" noisy.nii.gz 'sigma_mm = 0.5'
  "$bin" fit "$work/ph/noisy.toml" --out "$work/noisy" --truth "$work/ph/truth.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "noisy fit"
  s="$work/noisy/summary.json"
  echo "     0.5 mm noise: tumour $(json "$s" "round(d['modulus_pa']['tumour']['fitted_E_pa'])") Pa, truth RMS $(json "$s" "round(d['truth']['rms_mm'], 4)") mm"
  check "0.5 mm noise: >= 99% of elements within 1 mm of the truth" "$s" "d['truth']['within_1mm'] >= 0.99"
  echo "     Cramér–Rao standard errors: $(json "$s" "', '.join(f\"{k} {100 * v['relative_standard_error']:.1f}%\" for k, v in d['modulus_pa'].items())")"
  check "0.5 mm noise: Cramér–Rao standard error per region, every modulus within 3 of them" "$s" \
    "all(0 < v['relative_standard_error'] < 10 and abs(math.log(v['fitted_E_pa'] / T)) <= 3 * v['relative_standard_error'] for v, T in ((d['modulus_pa']['adipose'], 3250), (d['modulus_pa']['fibroglandular'], 6000), (d['modulus_pa']['tumour'], 16400)))"
  check "0.5 mm noise: the 15-element tumour's bound exceeds 10% (a data limit), the bulk tissues' does not" "$s" \
    "d['modulus_pa']['tumour']['relative_standard_error'] > 0.10 and d['modulus_pa']['adipose']['relative_standard_error'] < 0.10"

  nh='[materials.tumour]
law = "neo-hookean"
E = 16400.0
[materials.adipose]
law = "neo-hookean"
E = 3250.0
[materials.fibroglandular]
law = "neo-hookean"
E = 6000.0'
  scene nh "$nh" nh.nii.gz ""
  "$bin" fit "$work/ph/nh.toml" --make-observation "$work/ph/nh.nii.gz" >/dev/null
  "$bin" fit "$work/ph/nh.toml" --out "$work/nh" --truth "$work/ph/nh.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "neo-Hookean fit"
  check "neo-Hookean: tumour within 10%, >= 99% within 1 mm" "$work/nh/summary.json" \
    "abs(d['modulus_pa']['tumour']['fitted_E_pa'] / 16400 - 1) <= 0.10 and d['truth']['within_1mm'] >= 0.99"

  scene bis "$linear" truth.nii.gz 'method = "bisection"'
  "$bin" fit "$work/ph/bis.toml" --out "$work/bis" --truth "$work/ph/truth.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "bisection fit"
  check "bisection: converges (brackets closed), >= 99% within 1 mm" "$work/bis/summary.json" \
    "d['truth']['within_1mm'] >= 0.99 and 'bracket' in d['stop_reason']"

  scene bad "$linear" truth.nii.gz 'regions = "voxels"'
  "$bin" fit "$work/ph/bad.toml" --out "$work/bad" >"$work/bad.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "fit.regions" "$work/bad.txt" && pass "bad [fit] value: error naming fit.regions" || { fail "bad [fit] value"; cat "$work/bad.txt"; }
  ;;
resume)
  "$bin" fit "$work/ph/truth.toml" --out "$work/whole" --no-plots -q >/dev/null 2>&1 || fail "uninterrupted fit"
  "$bin" fit "$work/ph/truth.toml" --out "$work/parts" --no-plots -q --stop-after 2 >/dev/null 2>&1
  rc=$?
  [[ $rc -eq 3 && $(tail -n +2 "$work/parts/history.csv" | wc -l) -eq 2 ]] && pass "--stop-after 2: exit 3, 2 iterations saved" || fail "--stop-after (rc $rc)"
  "$bin" fit "$work/ph/truth.toml" --out "$work/parts" --no-plots >"$work/parts.txt" 2>&1 || fail "resumed fit"
  grep -q "^iteration   0" "$work/parts.txt" && fail "resumed fit redid iteration 0" || pass "resumed fit does not redo saved iterations"
  cmp -s <(cut -d, -f1-7 "$work/whole/history.csv") <(cut -d, -f1-7 "$work/parts/history.csv") && cmp -s "$work/whole/regions.csv" "$work/parts/regions.csv" \
    && pass "stopped + resumed fit: same history and moduli as uninterrupted" || { fail "stopped + resumed differs"; diff "$work/whole/history.csv" "$work/parts/history.csv"; }

  "$bin" fit "$work/ph/truth.toml" --out "$work/killed" --no-plots -q >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 3000); do [[ $(tail -n +2 "$work/killed/history.csv" 2>/dev/null | wc -l) -ge 2 ]] && break; sleep 0.01; done
  kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  [[ ! -e "$work/killed/summary.json" ]] && pass "kill -9 during the fit" || echo "     (the fit finished before the kill)"
  "$bin" fit "$work/ph/truth.toml" --out "$work/killed" --no-plots -q >/dev/null 2>&1 || fail "fit after kill"
  cmp -s "$work/whole/regions.csv" "$work/killed/regions.csv" && pass "killed + restarted fit: same moduli" || fail "killed + restarted fit differs"

  scene noisy "$linear" truth.nii.gz 'method = "bisection"'
  printf 'scene,truth\nph/truth.toml,ph/truth.nii.gz\nph/noisy.toml,\nph/truth.toml,ph/truth.nii.gz\n' >"$work/cases.csv"
  "$bin" fit --cases "$work/cases.csv" --out "$work/serial" --no-plots -q >/dev/null 2>&1 || fail "serial batch"
  [[ $(grep -c ',ok,' "$work/serial/metrics.csv") -eq 3 ]] && pass "batch: 3 cases ok" || fail "batch cases"
  "$bin" fit --cases "$work/cases.csv" --out "$work/bkill" --no-plots -q >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 6000); do [[ -e "$work/bkill/cases/0001/case.json" && -e "$work/bkill/progress/0002/history.csv" ]] && break; sleep 0.01; done
  kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  finished=$(ls "$work/bkill/cases" 2>/dev/null | grep -c '^[0-9]*$')
  [[ $finished -ge 1 && $finished -lt 3 ]] && pass "kill -9 of the batch after $finished of 3 cases" || fail "batch kill midway ($finished finished)"
  "$bin" fit --cases "$work/cases.csv" --out "$work/bkill" --no-plots >"$work/bkill.txt" 2>&1 || { fail "batch restart"; cat "$work/bkill.txt"; }
  grep -q "were finished before this run" "$work/bkill.txt" && pass "restart keeps the finished cases" || fail "restart reran finished cases"
  cmp -s "$work/serial/metrics.csv" "$work/bkill/metrics.csv" && pass "killed + restarted batch: same metrics.csv" \
    || { fail "killed batch metrics differ"; diff "$work/serial/metrics.csv" "$work/bkill/metrics.csv" | head; }
  ;;
mpi)
  printf 'scene,truth\nph/truth.toml,ph/truth.nii.gz\nph/truth.toml,\nph/truth.toml,ph/truth.nii.gz\n' >"$work/cases.csv"
  "$bin" fit --cases "$work/cases.csv" --out "$work/serial" --no-plots -q >/dev/null 2>&1 || fail "serial batch"
  mpirun=${MPIEXEC:-mpirun}
  root_flag=$([[ $(id -u) -eq 0 ]] && echo --allow-run-as-root)
  "$mpirun" $root_flag -n 2 --oversubscribe "$bin" fit --cases "$work/cases.csv" --out "$work/mpi" --no-plots -q >"$work/mpi.txt" 2>&1 \
    || { fail "mpirun -n 2 batch"; cat "$work/mpi.txt"; }
  cmp -s "$work/serial/metrics.csv" "$work/mpi/metrics.csv" && pass "mpirun -n 2: same metrics.csv as the serial batch" \
    || { fail "mpi metrics differ"; diff "$work/serial/metrics.csv" "$work/mpi/metrics.csv" | head; }
  [[ $(cut -d, -f1,3 "$work/mpi/timing.csv" | grep -c '^000[13],0$') -eq 2 ]] && pass "cases 1 and 3 on rank 0, case 2 on rank 1" || fail "partition"
  ;;
labels)
  label_scene
  "$bin" fit "$work/ph/lab.toml" --out "$work/lab" --truth "$work/ph/truth.nii.gz" --no-plots -q >"$work/lab.txt" 2>&1 \
    || { fail "label-map fit"; cat "$work/lab.txt"; }
  sed 's/^initial = .*/&\nmax_iterations = 0/' "$work/ph/lab.toml" >"$work/ph/lab0.toml"
  "$bin" fit "$work/ph/lab0.toml" --out "$work/lab0" --truth "$work/ph/truth.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "initial guess"
  s="$work/lab/summary.json"
  echo "     adipose $(json "$s" "round(d['modulus_pa']['adipose']['fitted_E_pa'])") Pa (from 1800, truth 3250), fibroglandular $(json "$s" "round(d['modulus_pa']['fibroglandular']['fitted_E_pa'])") (from 11000, truth 6000), tumour $(json "$s" "round(d['modulus_pa']['tumour']['fitted_E_pa'])") (from 6000, truth 16400)"
  echo "     surface RMS $(json "$s" "round(d['surface']['initial']['rms_mm'], 4)") -> $(json "$s" "round(d['surface']['final']['rms_mm'], 4)") mm, max $(json "$s" "round(d['surface']['final']['max_mm'], 3)") mm, within 1 mm $(json "$s" "d['surface']['final']['within_1mm']"); truth RMS $(json "$work/lab0/summary.json" "round(d['truth']['rms_mm'], 4)") -> $(json "$s" "round(d['truth']['rms_mm'], 4)") mm; $(json "$s" "d['forward_solves']") forward solves"
  check "label map: body and tumour boundaries observed" "$s" \
    "d['observation'] == 'surface' and d['surface']['faces_per_region']['body'] > 1000 and d['surface']['faces_per_region']['tumour'] > 0"
  check "label map: adipose and fibroglandular moduli at least halve their log error" "$s" \
    "all(abs(math.log(d['modulus_pa'][t]['fitted_E_pa'] / T)) <= 0.5 * abs(math.log(d['modulus_pa'][t]['initial_E_pa'] / T)) for t, T in (('adipose', 3250), ('fibroglandular', 6000)))"
  check "label map: surface distance falls (RMS, within 1 mm >= 99%)" "$s" \
    "d['surface']['final']['rms_mm'] < d['surface']['initial']['rms_mm'] and d['surface']['final']['within_1mm'] >= 0.99"
  truth0=$(json "$work/lab0/summary.json" "d['truth']['rms_mm']")
  check "label map: displacement error against the truth falls" "$s" "d['truth']['rms_mm'] < 0.5 * $truth0"
  head -1 "$work/lab/history.csv" | grep -q max_mm && pass "history.csv has max_mm" || fail "history.csv max_mm"
  sed 's/^initial = .*/&\nmethod = "bisection"/' "$work/ph/lab.toml" >"$work/ph/labbis.toml"
  "$bin" fit "$work/ph/labbis.toml" --out "$work/labbis" >"$work/labbis.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "fit.method" "$work/labbis.txt" && pass "bisection with a label map: error naming fit.method" || { fail "bisection with a label map"; cat "$work/labbis.txt"; }
  sed 's/^initial = .*/&\nobserved_label_values = [0, 9]/' "$work/ph/lab.toml" >"$work/ph/labbad.toml"
  "$bin" fit "$work/ph/labbad.toml" --out "$work/labbad" >"$work/labbad.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "label value 9" "$work/labbad.txt" && pass "unknown label value: error" || { fail "unknown label value"; cat "$work/labbad.txt"; }
  ;;
surface)
  "$bin" fit "$work/ph/truth.toml" --make-observed-surface "$work/ph/body.stl" >/dev/null || fail "--make-observed-surface"
  "$bin" fit "$work/ph/truth.toml" --make-observed-surface "$work/ph/tumour.stl" --surface-label 6 >/dev/null \
    || fail "--make-observed-surface --surface-label 6"
  scene surf "$wrong" truth.nii.gz 'initial = "materials"'
  sed -i 's/^dvf = .*/observed_surface = ["body.stl", "tumour.stl"]\nobserved_surface_values = [0, 6]/' "$work/ph/surf.toml"
  "$bin" fit "$work/ph/surf.toml" --out "$work/surf" --truth "$work/ph/truth.nii.gz" --no-plots -q >"$work/surf.txt" 2>&1 \
    || { fail "surface-mesh fit"; cat "$work/surf.txt"; }
  label_scene
  "$bin" fit "$work/ph/lab.toml" --out "$work/lab" --truth "$work/ph/truth.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "label-map fit"
  for d in surf lab; do
    s="$work/$d/summary.json"
    echo "     $d: adipose $(json "$s" "round(d['modulus_pa']['adipose']['fitted_E_pa'])") Pa (from 1800, truth 3250), fibroglandular $(json "$s" "round(d['modulus_pa']['fibroglandular']['fitted_E_pa'])") (from 11000, truth 6000), tumour $(json "$s" "round(d['modulus_pa']['tumour']['fitted_E_pa'])") (from 6000, truth 16400); surface RMS $(json "$s" "round(d['surface']['initial']['rms_mm'], 4)") -> $(json "$s" "round(d['surface']['final']['rms_mm'], 4)") mm; truth RMS $(json "$s" "round(d['truth']['rms_mm'], 4)") mm; $(json "$s" "d['forward_solves']") forward solves"
  done
  s="$work/surf/summary.json"
  check "surface mesh: body and tumour surfaces observed" "$s" \
    "d['observation'] == 'surface' and d['surface']['source'] == 'surface mesh' and d['surface']['faces_per_region']['body'] > 1000 and d['surface']['faces_per_region']['tumour'] > 0"
  check "surface mesh: adipose within 10%, fibroglandular within 20% of the truth (from -45% and +83%)" "$s" \
    "abs(d['modulus_pa']['adipose']['fitted_E_pa'] / 3250 - 1) <= 0.10 and abs(d['modulus_pa']['fibroglandular']['fitted_E_pa'] / 6000 - 1) <= 0.20"
  check "surface mesh: final surface RMS below 0.1 mm and under half the label map's (no staircase)" "$s" \
    "d['surface']['final']['rms_mm'] < 0.1 and d['surface']['final']['rms_mm'] < 0.5 * $(json "$work/lab/summary.json" "d['surface']['final']['rms_mm']")"
  err='max(abs(math.log(d["modulus_pa"][t]["fitted_E_pa"] / T)) for t, T in (("adipose", 3250), ("fibroglandular", 6000)))'
  check "surface mesh: moduli and displacements closer to the truth than from the label map" "$s" \
    "$err <= $(json "$work/lab/summary.json" "$err") and d['truth']['rms_mm'] < $(json "$work/lab/summary.json" "d['truth']['rms_mm']")"
  head -c 300 "$work/ph/body.stl" >"$work/ph/cut.stl"
  sed 's/^observed_surface = .*/observed_surface = "cut.stl"/; /^observed_surface_values/d' "$work/ph/surf.toml" >"$work/ph/surfcut.toml"
  "$bin" fit "$work/ph/surfcut.toml" --out "$work/surfcut" >"$work/surfcut.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "cut.stl" "$work/surfcut.txt" && grep -q "truncated" "$work/surfcut.txt" && pass "truncated STL: error naming the file" \
    || { fail "truncated STL"; cat "$work/surfcut.txt"; }
  printf 'solid open\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 10 0 0\n   vertex 0 10 0\n  endloop\n endfacet\nendsolid open\n' >"$work/ph/open.stl"
  sed 's/^observed_surface = .*/observed_surface = "open.stl"/; /^observed_surface_values/d' "$work/ph/surf.toml" >"$work/ph/surfopen.toml"
  "$bin" fit "$work/ph/surfopen.toml" --out "$work/surfopen" >"$work/surfopen.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "open.stl" "$work/surfopen.txt" && grep -q "not closed" "$work/surfopen.txt" && pass "open STL surface: error" \
    || { fail "open STL surface"; cat "$work/surfopen.txt"; }
  sed 's/^observed_surface_values = .*/observed_surface_values = [0]/' "$work/ph/surf.toml" >"$work/ph/surfcount.toml"
  "$bin" fit "$work/ph/surfcount.toml" --out "$work/surfcount" >"$work/surfcount.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "fit.observed_surface_values" "$work/surfcount.txt" && pass "one value per surface: error" \
    || { fail "observed_surface_values count"; cat "$work/surfcount.txt"; }
  ;;
reference)
  # the CT (the phantom) was taken supine: the observation is simulated from the unloaded state
  scene ref "$linear" ref_truth.nii.gz ""
  sed -i -e '/^from_posture = /d' -e 's/^\[fit\]/[reference_state]\nct_posture = "supine"\n[fit]/' "$work/ph/ref.toml"
  "$bin" fit "$work/ph/ref.toml" --make-observation "$work/ph/ref_truth.nii.gz" >/dev/null || fail "--make-observation with [reference_state]"
  "$bin" fit "$work/ph/ref.toml" --out "$work/on" --truth "$work/ph/ref_truth.nii.gz" --no-plots -q >"$work/on.txt" 2>&1 || { fail "fit from the unloaded state"; cat "$work/on.txt"; }
  (cat "$work/ph/ref.toml"; printf 'unloaded_reference = false\nfrom_posture = "supine"\n') >"$work/ph/refoff.toml"
  "$bin" fit "$work/ph/refoff.toml" --out "$work/off" --truth "$work/ph/ref_truth.nii.gz" --no-plots -q >/dev/null 2>&1 || fail "fit with the CT as rest shape"
  for d in on off; do
    echo "     $d: adipose $(json "$work/$d/summary.json" "round(d['modulus_pa']['adipose']['fitted_E_pa'])") (3250), fibroglandular $(json "$work/$d/summary.json" "round(d['modulus_pa']['fibroglandular']['fitted_E_pa'])") (6000), tumour $(json "$work/$d/summary.json" "round(d['modulus_pa']['tumour']['fitted_E_pa'])") (16400); truth RMS $(json "$work/$d/summary.json" "round(d['truth']['rms_mm'], 5)") mm; $(json "$work/$d/summary.json" "d['forward_solves']") forward solves, $(json "$work/$d/summary.json" "round(d['wall_time_s'], 1)") s"
  done
  err='max(abs(math.log(d["modulus_pa"][t]["fitted_E_pa"] / T)) for t, T in (("adipose", 3250), ("fibroglandular", 6000), ("tumour", 16400)))'
  check "unloaded reference: on by default with [reference_state], every modulus within 2%" "$work/on/summary.json" \
    "d['unloaded_reference'] and $err <= 0.02"
  off_err=$(json "$work/off/summary.json" "$err")
  off_rms=$(json "$work/off/summary.json" "d['truth']['rms_mm']")
  check "unloaded reference: moduli and displacements closer to the truth than with the CT as rest shape" "$work/on/summary.json" \
    "$err <= $off_err and d['truth']['rms_mm'] <= $off_rms"
  "$bin" fit "$work/ph/ref.toml" --out "$work/parts" --no-plots -q --stop-after 2 >/dev/null 2>&1
  "$bin" fit "$work/ph/ref.toml" --out "$work/parts" --no-plots -q >/dev/null 2>&1 || fail "resumed fit from the unloaded state"
  cmp -s "$work/on/regions.csv" "$work/parts/regions.csv" && cmp -s <(cut -d, -f1-7 "$work/on/history.csv") <(cut -d, -f1-7 "$work/parts/history.csv") \
    && pass "unloaded reference: stopped + resumed fit repeats the uninterrupted one" || { fail "resume from the unloaded state differs"; diff "$work/on/history.csv" "$work/parts/history.csv"; }
  sed 's/^tissues = .*/&\nfrom_posture = "upright"/' "$work/ph/ref.toml" >"$work/ph/refbad.toml"
  "$bin" fit "$work/ph/refbad.toml" --out "$work/refbad" >"$work/refbad.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "fit.from_posture" "$work/refbad.txt" && pass "from_posture other than the CT's: error" || { fail "from_posture mismatch"; cat "$work/refbad.txt"; }
  sed 's/^tissues = .*/&\nunloaded_reference = true/' "$work/ph/truth.toml" >"$work/ph/refnone.toml"
  "$bin" fit "$work/ph/refnone.toml" --out "$work/refnone" >"$work/refnone.txt" 2>&1
  [[ $? -ne 0 ]] && grep -q "reference_state" "$work/refnone.txt" && pass "unloaded_reference without [reference_state]: error" || { fail "unloaded_reference without [reference_state]"; cat "$work/refnone.txt"; }
  ;;
*) echo "unknown mode $mode"; exit 2 ;;
esac
finish
