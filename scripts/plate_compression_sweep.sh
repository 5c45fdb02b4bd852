#!/usr/bin/env bash
# Plate compression of a hyperelastic cube at ten load levels, both laws, float and double
# (docs/VALIDATION.md, "Plate compression at every load level"). Each level is its own run to
# equilibrium. Scenes go to out-sweep/ (git-ignored):
#   here:   bash scripts/plate_compression_sweep.sh scenes
#   device: bash scripts/gpu_run.sh run bash scripts/plate_compression_sweep.sh run   (→ $OUT/results.tar.gz)
#   here:   /usr/bin/python3 scripts/plate_compression_table.py RESULTS_DIR docs/results/plate_compression_levels.csv
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$root/out-sweep
n=10 h=0.002 speed=0.05

scene() {  # law precision stretch → scene on stdout
  local law=$1 precision=$2 stretch=$3 material
  if [ "$law" = ogden ]; then
    material=$'law = "ogden"\nmu = [1200.0, -300.0]\nalpha = [4.0, -2.0]'
  else
    material=$'law = "neo-hookean"\nE = 3000.0'
  fi
  cat <<T
[model]
spacing = $h
[[model.shape]]
kind = "box"
min = [0, 0, 0]
max = [$(awk "BEGIN{print $n*$h}"), $(awk "BEGIN{print $n*$h}"), $(awk "BEGIN{print $n*$h}")]
label = "soft"
[materials.soft]
$material
nu = 0.495
density = 1000.0
[solver]
precision = "$precision"
damping = 300.0
dashpot_ratio = 0.1
[[indenter]]
kind = "plate"
start = [0, 0, $(awk "BEGIN{print 0.5*$h}")]
normal = [0, 0, 1]
[[indenter]]
kind = "plate"
start = [0, 0, $(awk "BEGIN{print ($n-0.5)*$h}")]
normal = [0, 0, -1]
velocity = [0, 0, -$speed]
travel_time = $(awk "BEGIN{print (1-$stretch)*($n-1)*$h/$speed}")
[stop]
equilibrium = $([ "$precision" = float ] && echo 1e-5 || echo 1e-8)
max_steps = 200000
T
}

case "${1:-}" in
  scenes)
    rm -rf "$dir" && mkdir -p "$dir"
    for law in nh ogden; do
      for stretch in 0.95 0.9 0.85 0.8 0.75 0.7 0.65 0.6 0.55 0.5; do
        for precision in double float; do scene $law $precision $stretch >"$dir/${law}_${precision}_l$stretch.toml"; done
      done
    done
    ;;
  run)
    res=$(mktemp -d)
    for s in "$dir"/*.toml; do
      name=$(basename "$s" .toml)
      voxbreast simulate "$s" --out "$res/$name" --quiet | grep -v '^wrote' | sed "s/^/$name: /"
    done
    tar -C "$res" -czf "$OUT/results.tar.gz" .
    ;;
  *)
    echo "usage: $0 scenes | run" >&2
    exit 2
    ;;
esac
