#!/usr/bin/env bash
# Probing on a GPU, in one device call (a few minutes): the palpation sample (timing) and
# the palpation truth-cube sweep at 2 mm spacing (64,000 elements, presses every 4 mm).
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/gpu_probe.sh            (carry [".device-pkgs"]; writes $OUT/probe)
#   here:   bash scripts/gpu_probe.sh plot FETCHED/probe   # table and PNGs into out/gpu_probe/
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

if [[ "${1:-}" == "plot" ]]; then
  dir=${2:?fetched probe folder}
  work=out/gpu_probe
  rm -rf "$work" && mkdir -p "$work" && cp -r "$dir"/. "$work"/ && chmod -R u+w "$work"
  /usr/bin/python3 scripts/palpation_sweep.py --out "$work/sweep_2mm" --spacing 0.002 --pitch 0.004
  /usr/bin/python3 scripts/palpation_sweep.py --out "$work/sweep_2mm_depth2" --spacing 0.002 --pitch 0.004 --depth 0.002
  /usr/bin/python3 scripts/plot_probe.py "$work/sample"
  cat "$work/sample_time.txt"
  echo "tables: $work/sweep_2mm/table.md, $work/sweep_2mm_depth2/table.md; PNGs there and in $work/sample"
  exit 0
fi

out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/probe
mkdir -p "$out"
bash scripts/gpu_run.sh run voxbreast info >"$out/device.txt" 2>&1 || true
SECONDS=0
bash scripts/gpu_run.sh run voxbreast probe data-samples/palpation/scene.toml --device gpu --out "$out/sample" \
  >"$out/sample.log" 2>&1
echo "palpation sample (8,000 elements, 17 presses x 4 increments): ${SECONDS} s wall" \
  | tee "$out/sample_time.txt"
tail -3 "$out/sample.log"
if command -v python3 >/dev/null; then
  SECONDS=0
  python3 scripts/palpation_sweep.py --voxbreast "bash scripts/gpu_run.sh run voxbreast" --device gpu \
    --spacing 0.002 --pitch 0.004 --out "$out/sweep_2mm" --no-plots 2>&1 | tee "$out/sweep.log"
  echo "sweep at 2 mm: ${SECONDS} s wall" | tee -a "$out/sample_time.txt"
  # The 4 mm presses fold the 2 mm lattice over shallow tumours (docs/PROBING.md, "Validity"):
  # the same sweep pressed one spacing (2 mm) deep.
  SECONDS=0
  python3 scripts/palpation_sweep.py --voxbreast "bash scripts/gpu_run.sh run voxbreast" --device gpu \
    --spacing 0.002 --pitch 0.004 --depth 0.002 --out "$out/sweep_2mm_depth2" --no-plots 2>&1 | tee "$out/sweep_depth2.log"
  echo "sweep at 2 mm, presses 2 mm deep: ${SECONDS} s wall" | tee -a "$out/sample_time.txt"
else
  echo "no python3 on the device: the sweep is skipped" | tee "$out/sweep.log"
fi
