#!/usr/bin/env bash
# The full speed/accuracy study and the cube throughput on a GPU, in one device call (~5 min on an
# H200; results are rewritten after every run, so a call cut short keeps what it did).
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/bench_gpu.sh            (run tool, carry [".device-pkgs"]; writes $OUT/bench)
#   here:   bash scripts/bench_gpu.sh plot FETCHED/bench h200_DATE_COMMIT   # docs/results/, docs/img/ files
#           (named by device, date and commit, as bench.json's `device`, `date`, `commit` say)
# $BENCH_TIMEOUT (s) stops the study early but still packs what it wrote.
# Extra bench options go in $BENCH_ARGS, e.g. BENCH_ARGS="--scenes phantom_large --laws neo-hookean".
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

if [[ "${1:-}" == "plot" ]]; then
  dir=${2:?folder with bench.csv}
  name=${3:?name: device_date_commit, e.g. h200_2026-12-02_a7560de}
  /usr/bin/python3 tests/apps/check_bench.py "$dir" || echo "check_bench found problems (see above)"
  cp "$dir/bench.csv" "docs/results/bench_study_$name.csv"
  cp "$dir/bench.json" "docs/results/bench_study_$name.json"
  [[ -f "$dir/throughput.csv" ]] && cp "$dir/throughput.csv" "docs/results/bench_throughput_$name.csv"
  /usr/bin/python3 scripts/plot_bench_study.py "$dir" "docs/img/bench_study_$name" "$name"
  [[ -f "$dir/throughput.csv" ]] && /usr/bin/python3 scripts/plot_bench.py "$dir/throughput.csv" "docs/img/bench_throughput_$name.png" "$name"
  exit 0
fi

out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/bench
mkdir -p "$out"
bash scripts/gpu_run.sh run voxbreast info >"$out/device.txt" 2>&1 || true
# SM clock and power every 250 ms: long float runs reach the card's power cap and clock down
# (docs/PERFORMANCE.md, "Denormals and the power cap"), which the timed rates then include.
smi=""
if command -v nvidia-smi >/dev/null; then
  nvidia-smi --query-gpu=timestamp,clocks.sm,power.draw,clocks_throttle_reasons.active --format=csv -lms 250 \
    >"$out/clocks.csv" 2>&1 &
  smi=$!
fi
# Full study (column, phantom, ~1.5M-element phantom) and the throughput series (cubes, the
# phantom at ~1.5M elements).
# shellcheck disable=SC2086
${BENCH_TIMEOUT:+timeout $BENCH_TIMEOUT} bash scripts/gpu_run.sh run voxbreast bench --device gpu --out "$out" --phantom data-samples/phantom/scene.toml \
  --sizes 22 33 50 80 115 160 --breast-large ${BENCH_ARGS:-} 2>&1 | tee "$out/bench.log" || echo "bench stopped early (see bench.log)"
[[ -n "$smi" ]] && kill "$smi" 2>/dev/null || true
# A failed sanity check is reported, and the archive is still packed.
if command -v python3 >/dev/null; then python3 tests/apps/check_bench.py "$out" | tail -20 || true; fi
# Few files come back from the device: one archive as well (unpack with tar -xzf bench.tar.gz).
tar -C "$out/.." -czf "$out/../bench.tar.gz" bench
