#!/usr/bin/env bash
# Is "tumour modulus within 10% with 0.5 mm noise" a data limit? (docs/VALIDATION.md,
# "Noise and the Cramér–Rao bound"). The noisy variant of scripts/validate_fit.sh (same phantoms,
# seed, initial guess, σ = 0.5 mm) per case; each fit's summary.json carries the Cramér–Rao
# standard error of every region's ln E from its last Jacobian (modulus_pa.*.relative_standard_error),
# tabulated next to the error the fit made.
#   bash scripts/fit_noise_bound.sh [OUT_DIR] [SPACING_MM]      (default out/fit_noise_bound, 4 mm)
set -euo pipefail
out=${1:-out/fit_noise_bound}
spacing=${2:-4}
bin=${VOXBREAST_BIN:-build/apps/voxbreast}
here=$(cd "$(dirname "$0")" && pwd)
py=$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)
mkdir -p "$out"
cases=$(grep -v '^#' "$here/../data-samples/phantom/fit_cases.txt")  # name type E_pa x y z radius
scene() {  # file, tumour E, adipose E, gland E, observation, extra [fit] lines
  cat >"$1" <<TOML
$(cat "$here/../data-samples/phantom/fit_model.toml")
[materials.tumour]
E = $2
[materials.adipose]
E = $3
[materials.fibroglandular]
E = $4
$(cat "$here/../data-samples/phantom/fit_solver.inc")
[fit]
from_posture = "supine"
dvf = "$5"
tissues = ["adipose", "fibroglandular", "tumour"]
$6
TOML
}
echo "| case | tumour elements | tumour E fitted (kPa) | true (kPa) | error | Cramér–Rao SE (tumour) | error / SE | adipose error (SE) | fibroglandular error (SE) |" >"$out/table.md"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|" >>"$out/table.md"
while read -r name type E x y z r; do
  d="$out/$name"
  [[ -e "$d/ct.nii.gz" ]] || "$bin" phantom --out "$d" --spacing "$spacing" --tumour "$type,$x,$y,$z,$r" >/dev/null
  scene "$d/truth.toml" "$E" 3250.0 6000.0 truth.nii.gz ""
  scene "$d/noisy.toml" 10000.0 2000.0 10000.0 noisy.nii.gz "sigma_mm = 0.5"
  [[ -e "$d/noisy.nii.gz" ]] || "$bin" fit "$d/truth.toml" --make-observation "$d/noisy.nii.gz" --noise-mm 0.5 --seed 7 >/dev/null
  [[ -e "$d/fit/summary.json" ]] || "$bin" fit "$d/noisy.toml" --out "$d/fit" --no-plots -q >/dev/null
  "$py" - "$d/fit/summary.json" "$name" "$E" >>"$out/table.md" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1])); m = d["modulus_pa"]; E = float(sys.argv[3])
def err(t, true): return m[t]["fitted_E_pa"] / true - 1
def se(t):
    s = m[t].get("relative_standard_error"); return math.inf if s is None else s
t = m["tumour"]
print(f"| {sys.argv[2]} | {t['elements']} | {t['fitted_E_pa'] / 1e3:.2f} | {E / 1e3:.1f} | {100 * err('tumour', E):+.1f}% | "
      f"{100 * se('tumour'):.1f}% | {abs(math.log(t['fitted_E_pa'] / E)) / se('tumour'):.2f} | "
      f"{100 * err('adipose', 3250):+.2f}% ({100 * se('adipose'):.2f}%) | {100 * err('fibroglandular', 6000):+.2f}% ({100 * se('fibroglandular'):.2f}%) |")
PY
done <<<"$cases"
cat "$out/table.md"
