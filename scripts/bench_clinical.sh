#!/usr/bin/env bash
# The main job at clinical image sizes (docs/BENCHMARKS.md): the phantom at 0.75 mm (5.9 M voxels)
# and as a 512 × 512 × 200 planning CT at 0.98 × 0.98 × 2.5 mm (52 M voxels), each run end to end
# by `voxbreast bench --job`, which times every phase and the image outputs' peak memory.
#   VOXBREAST_BIN=build/apps/voxbreast bash scripts/bench_clinical.sh out/bench_clinical
set -euo pipefail
bin=${VOXBREAST_BIN:-build/apps/voxbreast}
out=${1:-out/bench_clinical}
mkdir -p "$out"
"$bin" phantom --out "$out/phantom_0.75mm" --spacing 0.75
"$bin" phantom --out "$out/planning_512" --spacing 0.98 0.98 2.5 --dims 512 512 200
"$bin" bench --no-study --out "$out/bench" --job "$out/phantom_0.75mm/scene.toml" --job "$out/planning_512/scene.toml"
