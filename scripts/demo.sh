#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: install dependencies, build, and run the main job
# (the bundled breast phantom, prone under gravity) into ./out/phantom.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
"${VOXBREAST_BUILD_DIR:-$root/build}/apps/voxbreast" simulate "$root/data-samples/breast_phantom.toml" \
  --out "${1:-$root/out/phantom}"
