#!/usr/bin/env bash
# Sample device-design sweep (docs/POSITIONING.md, "Comparing designs"): the positioning sample
# (phantom CT supine → prone, unloaded reference state, two inflating rings) with the front ring
# at three major radii — the tighter the ring, the deeper it grips — each with its reproducibility
# study cut to 2 postures, so the tumour's spread with and without the device is a column of
# metrics.csv next to the ring forces and pressures. A design comparison needs the static answers
# only, so the sweep runs them by dynamic relaxation (docs/PHYSICS.md §12): 3 cases, 10-11 s each
# on a 2-core CPU (Heun: 67-92 s each, the same spreads to 0.0013 mm).
#   bash data-samples/phantom/sweep_device.sh [OUT_DIR] [more voxbreast sweep options, e.g. --devices all]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${VOXBREAST_BIN:-$here/../../build/apps/voxbreast}
out=${1:-out/device_sweep}
shift || true
exec "$bin" sweep "$here/scene_device.toml" \
  --vary device.torus.2.major_radius=0.053:0.056:3 \
  --vary reproducibility.perturbations=2 \
  --vary solver.integrator=relaxation \
  --out "$out" "$@"
