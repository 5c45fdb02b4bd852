#!/usr/bin/env bash
# Validation of the two observation/forward-model options of docs/FIT.md
# (docs/VALIDATION.md, "Label-map observations and the unloaded reference state"):
#   labels     — the observation is the phantom's label map after the supine → prone change
#                (simulated with the true moduli, voxelised at 1 mm), matched by surface distances
#                of the body outline and the tumour (labels_body: the body outline only);
#   surface    — the same boundaries as surface meshes (STL, --make-observed-surface), matched by
#                exact point-to-triangle distances (surface_body: the body outline only);
#   ref_on/off — the truth is simulated from the unloaded reference state ([reference_state]
#                ct_posture = "supine"); fitted with the option (default) and without it (the CT
#                as rest shape, from_posture = "supine"); linear and neo-Hookean tissues.
# Initial guess as in scripts/validate_fit.sh (table adipose 2 kPa, fibroglandular 10 kPa, tumour
# 10 kPa; HU rule). Tumour cases: the larger lesions of validate_fit.sh (neo-Hookean: the first).
#   bash scripts/validate_fit_observations.sh [OUT_DIR] [SPACING_MM]   (default out/fit_observations, 4)
# Writes OUT_DIR/table.md. Reruns skip finished fits. REFERENCE=0 skips the ref_on/off fits.
set -euo pipefail
out=${1:-out/fit_observations}
spacing=${2:-4}
bin=${VOXBREAST_BIN:-build/apps/voxbreast}
py=$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)
mkdir -p "$out"
# name type E x y z radius laws-of-the-reference-comparison (neo-Hookean fits are ~10× slower)
cases="dcis_r10 dcis 16400 -20 -15 -15 10 linear,neo-hookean
idc_r10 idc 20000 20 -15 -10 10 linear
fibroadenoma_r12 fibroadenoma 6400 -10 -15 20 12 linear"

scene() {  # file, tumour E, law, [fit] observation + extra lines, adipose E, gland E, extra sections
  local law_line=""
  [[ $3 == neo-hookean ]] && law_line='law = "neo-hookean"'
  cat >"$1" <<TOML
$(cat "$(dirname "$0")/../data-samples/phantom/fit_model.toml")
[materials.tumour]
$law_line
E = $2
[materials.adipose]
$law_line
E = ${5:-3250.0}
[materials.fibroglandular]
$law_line
E = ${6:-6000.0}
$(cat "$(dirname "$0")/../data-samples/phantom/fit_solver.inc")
${7:-}
[fit]
tissues = ["adipose", "fibroglandular", "tumour"]
$4
TOML
}

fit() {  # scene, out, truth
  [[ -e "$2/summary.json" ]] || "$bin" fit "$1" --out "$2" --truth "$3" --no-plots -q >/dev/null
}

ref='[reference_state]
ct_posture = "supine"'
while read -r name type E x y z r laws; do
  d="$out/$name"
  [[ -e "$d/ct.nii.gz" ]] || "$bin" phantom --out "$d" --spacing "$spacing" --tumour "$type,$x,$y,$z,$r" >/dev/null
  scene "$d/truth.toml" "$E" linear 'from_posture = "supine"
dvf = "truth.nii.gz"'
  [[ -e "$d/labels_obs.nii.gz" ]] || "$bin" fit "$d/truth.toml" --make-observation "$d/truth.nii.gz" \
    --make-observed-labels "$d/labels_obs.nii.gz" --labels-subdivide "$spacing" >/dev/null
  scene "$d/labels.toml" 10000.0 linear 'from_posture = "supine"
observed_labels = "labels_obs.nii.gz"' 2000.0 10000.0
  scene "$d/labels_body.toml" 10000.0 linear 'from_posture = "supine"
observed_labels = "labels_obs.nii.gz"
observed_label_values = [0]' 2000.0 10000.0
  fit "$d/labels.toml" "$d/labels" "$d/truth.nii.gz"
  fit "$d/labels_body.toml" "$d/labels_body" "$d/truth.nii.gz"
  [[ -e "$d/body_obs.stl" ]] || "$bin" fit "$d/truth.toml" --make-observed-surface "$d/body_obs.stl" >/dev/null
  tumour_label=$(grep -m1 '= "tumour"' "$(dirname "$0")/../data-samples/phantom/fit_model.toml" | cut -d' ' -f1)
  [[ -e "$d/tumour_obs.stl" ]] || "$bin" fit "$d/truth.toml" --make-observed-surface "$d/tumour_obs.stl" \
    --surface-label "$tumour_label" >/dev/null
  scene "$d/surface.toml" 10000.0 linear "from_posture = \"supine\"
observed_surface = [\"body_obs.stl\", \"tumour_obs.stl\"]
observed_surface_values = [0, $tumour_label]" 2000.0 10000.0
  scene "$d/surface_body.toml" 10000.0 linear 'from_posture = "supine"
observed_surface = "body_obs.stl"' 2000.0 10000.0
  fit "$d/surface.toml" "$d/surface" "$d/truth.nii.gz"
  fit "$d/surface_body.toml" "$d/surface_body" "$d/truth.nii.gz"
  [[ ${REFERENCE:-1} == 0 ]] && laws=""
  for law in ${laws//,/ }; do
    s=${law%%-*}
    scene "$d/ref_truth_$s.toml" "$E" $law "dvf = \"ref_truth_$s.nii.gz\"" 3250.0 6000.0 "$ref"
    [[ -e "$d/ref_truth_$s.nii.gz" ]] || "$bin" fit "$d/ref_truth_$s.toml" --make-observation "$d/ref_truth_$s.nii.gz" >/dev/null
    scene "$d/ref_on_$s.toml" 10000.0 $law "dvf = \"ref_truth_$s.nii.gz\"" 2000.0 10000.0 "$ref"
    scene "$d/ref_off_$s.toml" 10000.0 $law "dvf = \"ref_truth_$s.nii.gz\"
unloaded_reference = false
from_posture = \"supine\"" 2000.0 10000.0 "$ref"
    fit "$d/ref_on_$s.toml" "$d/ref_on_$s" "$d/ref_truth_$s.nii.gz"
    fit "$d/ref_off_$s.toml" "$d/ref_off_$s" "$d/ref_truth_$s.nii.gz"
  done
  echo "$name done"
done <<<"$cases"

"$py" - "$out" <<'PY' | tee "$out/table.md"
import json, os, sys
out = sys.argv[1]
truth = {"dcis_r10": 16400, "idc_r10": 20000, "fibroadenoma_r12": 6400}
print("| case | variant | tumour E (kPa) | true | error | adipose error | fibroglandular error | surface RMS initial → final (mm) | surface max (mm) | surface within 1 mm | RMS vs truth (mm) | max vs truth (mm) | within 1 mm of truth | forward solves | wall (s) |")
print("|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|")
for case, T in truth.items():
    for v in ["labels", "labels_body", "surface", "surface_body", "ref_on_linear", "ref_off_linear", "ref_on_neo", "ref_off_neo"]:
        p = os.path.join(out, case, v, "summary.json")
        if not os.path.exists(p):
            continue
        d = json.load(open(p))
        m = d["modulus_pa"]
        err = lambda t, true: f"{100 * (m[t]['fitted_E_pa'] / true - 1):+.2f}%"
        s = d.get("surface")
        surf = (f"{s['initial']['rms_mm']:.3f} → {s['final']['rms_mm']:.3f}", f"{s['final']['max_mm']:.2f}",
                f"{100 * s['final']['within_1mm']:.2f}%") if s else ("—", "—", "—")
        t = d["truth"]
        print(f"| {case} | {v} | {m['tumour']['fitted_E_pa'] / 1e3:.2f} | {T / 1e3:.1f} | {err('tumour', T)} | "
              f"{err('adipose', 3250)} | {err('fibroglandular', 6000)} | {surf[0]} | {surf[1]} | {surf[2]} | "
              f"{t['rms_mm']:.4f} | {t['max_mm']:.3f} | {100 * t['within_1mm']:.2f}% | {d['forward_solves']} | {d['wall_time_s']:.1f} |")
PY
