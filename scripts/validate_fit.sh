#!/usr/bin/env bash
# Fit validation (docs/VALIDATION.md, "Fitting: inverse fitting of moduli"), the source paper's protocol:
# a phantom with one spherical tumour of literature stiffness per case (DCIS, invasive ductal
# carcinoma, fibroadenoma; two sizes, different positions), its supine → prone displacement
# simulated with the true moduli (adipose 3.25 kPa, fibroglandular 6 kPa, the tumour's literature
# value), then the model reset to an initial guess that does not know them (the fit scenes' table
# says adipose 2 kPa, fibroglandular 10 kPa, tumour 10 kPa; the HU rule maps the CT between the
# first two) and fitted; reported: the fraction of elements whose fitted displacement is within
# 1 mm of the truth and the recovered moduli.
# Variants per case: linear Gauss-Newton, + 0.5 mm Gaussian noise, neo-Hookean, bisection.
#   bash scripts/validate_fit.sh [OUT_DIR] [SPACING_MM]      (default out/fit_validation, 4 mm)
# Runs as one `voxbreast fit --cases` batch (resumable: rerun to continue), then tabulates
# (scripts/fit_validation_table.py → OUT_DIR/table.md, OUT_DIR/validation.png).
set -euo pipefail
out=${1:-out/fit_validation}
spacing=${2:-4}
bin=${VOXBREAST_BIN:-build/apps/voxbreast}
here=$(cd "$(dirname "$0")" && pwd)
py=$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)
mkdir -p "$out/cases"
cases=$(grep -v '^#' "$here/../data-samples/phantom/fit_cases.txt")  # name type E_pa x y z radius

scene() {  # file, tumour E, law (linear | neo-hookean), observation, extra [fit] lines, adipose E, gland E
  local law_line=""
  [[ $3 == neo-hookean ]] && law_line='law = "neo-hookean"'
  cat >"$1" <<TOML
$(cat "$here/../data-samples/phantom/fit_model.toml")
[materials.tumour]
$law_line
E = $2
[materials.adipose]
$law_line
E = ${6:-3250.0}
[materials.fibroglandular]
$law_line
E = ${7:-6000.0}
$(cat "$here/../data-samples/phantom/fit_solver.inc")
[fit]
from_posture = "supine"
dvf = "$4"
tissues = ["adipose", "fibroglandular", "tumour"]
$5
TOML
}

echo "scene,truth" >"$out/cases.csv.tmp"
while read -r name type E x y z r; do
  d="$out/cases/$name"
  if [[ ! -e "$d/ct.nii.gz" ]]; then
    "$bin" phantom --out "$d" --spacing "$spacing" --tumour "$type,$x,$y,$z,$r" >/dev/null
  fi
  # the truth (observations only) and the fits (the guess's table)
  scene "$d/truth_linear.toml" "$E" linear truth.nii.gz ""
  scene "$d/truth_nh.toml" "$E" neo-hookean truth_nh.nii.gz ""
  scene "$d/linear.toml" 10000.0 linear truth.nii.gz "" 2000.0 10000.0
  scene "$d/noisy.toml" 10000.0 linear noisy.nii.gz "sigma_mm = 0.5" 2000.0 10000.0
  scene "$d/neo_hookean.toml" 10000.0 neo-hookean truth_nh.nii.gz "" 2000.0 10000.0
  scene "$d/bisection.toml" 10000.0 linear truth.nii.gz 'method = "bisection"' 2000.0 10000.0
  [[ -e "$d/truth.nii.gz" ]] || "$bin" fit "$d/truth_linear.toml" --make-observation "$d/truth.nii.gz" >/dev/null
  [[ -e "$d/noisy.nii.gz" ]] || "$bin" fit "$d/truth_linear.toml" --make-observation "$d/noisy.nii.gz" --noise-mm 0.5 --seed 7 >/dev/null
  [[ -e "$d/truth_nh.nii.gz" ]] || "$bin" fit "$d/truth_nh.toml" --make-observation "$d/truth_nh.nii.gz" >/dev/null
  for v in linear noisy bisection; do echo "cases/$name/$v.toml,cases/$name/truth.nii.gz" >>"$out/cases.csv.tmp"; done
  echo "cases/$name/neo_hookean.toml,cases/$name/truth_nh.nii.gz" >>"$out/cases.csv.tmp"
done <<<"$cases"
mv "$out/cases.csv.tmp" "$out/cases.csv"
"$bin" fit --cases "$out/cases.csv" --out "$out/batch" --no-plots
"$py" "$here/fit_validation_table.py" "$out" "$spacing"
