#!/usr/bin/env bash
# Fit timing: one inverse fit of a ~36k-element phantom with 8 regions on the GPU (goal ≤ 60 s),
# with the Jacobian's perturbed solves one at a time (fit.batch = 1) and batched on the device
# (fit.batch = 9, BATCH=N to change: all 9 perturbed copies in one simulator; "auto" now solves one
# at a time, docs/FIT.md "Batched solves"). Both summaries' jacobian_timing (setup, uploads,
# relaxation, read-back, steps) go to $OUT/fit/timing.txt: where a batch wins or loses.
#   here:   cmake --build build --target voxbreast test_physics test_fit && bash scripts/gpu_run.sh prepare
#   device: bash scripts/gpu_fit.sh        (run tool, carry [".device-pkgs"]; writes $OUT/fit)
#           First, when the bundle has test_fit: batched = sequential solves on the GPU too
#           ($OUT/fit/test_fit.txt). SPACING_MM=2.5 for a larger phantom.
#   local:  OUT=/tmp/gpufit VOXBREAST_BIN=build/apps/voxbreast DEVICE=cpu MAX_ITERATIONS=1 bash scripts/gpu_fit.sh
# The phantom (3.2 mm voxels, one IDC tumour) is built there; its supine → prone displacement with
# the material table's moduli is the observation; the fit starts from the HU guess with 8 regions
# (adipose, fibroglandular and tumour elements in 60 mm blocks: 9 regions, no block size gives
# exactly 8 on this phantom) and runs Gauss-Newton for at most 10 iterations, double precision.
# The wall times are in $OUT/fit/timing.txt (whole command) and $OUT/fit/{sequential,batched}/
# summary.json (wall_time_s: fit iterations; jacobian_wall_time_s: the perturbed solves; batch).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/fit
device=${DEVICE:-gpu}
spacing=${SPACING_MM:-3.2}
mkdir -p "$out"
if [[ -n "${VOXBREAST_BIN:-}" ]]; then vb() { "$VOXBREAST_BIN" "$@"; }; else vb() { bash scripts/gpu_run.sh run voxbreast "$@"; }; fi
vb info >"$out/device.txt" 2>&1 || true
if [[ -z "${VOXBREAST_BIN:-}" ]] && tar -tJf .device-pkgs/bundle.tar.xz bin/test_fit >/dev/null 2>&1; then
  bash scripts/gpu_run.sh run test_fit --gtest_filter='*Batch*:TiledLattice.*:ForwardModel*' >"$out/test_fit.txt" 2>&1 || true
  tail -n 3 "$out/test_fit.txt"
fi
vb phantom --out "$out/ph" --spacing "$spacing" --tumour idc,15,-20,5,10 >/dev/null
write_scene() {  # file, precision, batch
  cat >"$1" <<TOML
$(cat "$root/data-samples/phantom/fit_model.toml")
[solver]
integrator = "relaxation"
precision = "$2"
check_every = 10
[gravity]
posture = "prone"
[fit]
from_posture = "supine"
dvf = "truth.nii.gz"
regions = "blocks"
block_mm = 60
tissues = ["adipose", "fibroglandular", "tumour"]
max_iterations = ${MAX_ITERATIONS:-10}
batch = $3
TOML
}
write_scene "$out/ph/fit_sequential.toml" double 1
write_scene "$out/ph/fit_batched.toml" double "${BATCH:-9}"
{ time vb fit "$out/ph/fit_sequential.toml" --device "$device" --make-observation "$out/ph/truth.nii.gz"; } 2>&1 | tee "$out/timing.txt"
for b in sequential batched; do
  echo "== fit, double precision, $b perturbed solves" | tee -a "$out/timing.txt"
  { time vb fit "$out/ph/fit_$b.toml" --device "$device" --out "$out/$b" --truth "$out/ph/truth.nii.gz" --no-plots \
      ${STOP_AFTER:+--stop-after $STOP_AFTER}; } 2>&1 | tee -a "$out/timing.txt" || true
done
for b in sequential batched; do
  echo "== $b" | tee -a "$out/timing.txt"
  grep -h '"elements"\|"regions"\|"batch"\|"wall_time_s"\|"jacobian_wall_time_s"\|"forward_solves"\|"iterations"' \
    "$out/$b/summary.json" 2>/dev/null | tee -a "$out/timing.txt" || true
  python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['jacobian_timing']; print('  jacobian_timing:', ', '.join(f'{k} {v:.4g}' for k, v in t.items()))" \
    "$out/$b/summary.json" 2>/dev/null | tee -a "$out/timing.txt" || true
done
