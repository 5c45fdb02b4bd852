#!/usr/bin/env bash
# Sample sweep (docs/SWEEP.md): the phantom CT settling under gravity, for three adipose
# stiffnesses (the scene leaves adipose at its default modulus, so the key is added: '+') and two
# postures: 6 cases, about a minute on a 2-core CPU with PoCL.
#   bash data-samples/phantom/sweep.sh [OUT_DIR] [more voxbreast sweep options, e.g. --devices all]
#   mpirun -n 2 build/apps/voxbreast sweep ...    (the same command, one device per rank)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${VOXBREAST_BIN:-$here/../../build/apps/voxbreast}
out=${1:-out/phantom_sweep}
shift || true
exec "$bin" sweep "$here/scene.toml" \
  --vary +materials.adipose.E=2000:6000:3 \
  --vary gravity.posture=prone,supine \
  --out "$out" "$@"
