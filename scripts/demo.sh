#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: install dependencies, build, and run the main job:
# the bundled phantom planning CT (DICOM series + label map) settling prone, written to
# ./out/phantom as summary.json, result.h5, DVFs, the warped CT (NIfTI + DICOM) and field maps.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
"${VOXBREAST_BUILD_DIR:-$root/build}/apps/voxbreast" simulate "$root/data-samples/phantom/scene_dicom.toml" \
  --out "${1:-$root/out/phantom}"
