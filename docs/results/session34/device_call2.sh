#!/usr/bin/env bash
# Session 34's second device call (the first ran out of time after the 36k rows): the 1.5M cube,
# linear + Heun float (issue 7's 60% row), with this build and the reference c4011a3, then
# gpu_fit.sh's fit timings. Text results only.
set -uo pipefail
cd "$(dirname "$0")/../../.."
ref=$(mktemp -d) && tar -C "$ref" -xJf .device-pkgs/ref.tar.xz
b=(bench --device gpu --quick --no-study --sizes 115 --laws linear)
for r in 1 2; do
  { echo "== 1.5M_new_r$r"; bash scripts/gpu_run.sh run voxbreast "${b[@]}" --out "$(mktemp -d)"; } >>"$OUT/rows_1.5M.txt" 2>&1
  { echo "== 1.5M_ref_r$r"; bash scripts/gpu_run.sh run "$ref/bin/voxbreast" "${b[@]}" --out "$(mktemp -d)"; } >>"$OUT/rows_1.5M.txt" 2>&1
done
timeout 300 bash scripts/gpu_fit.sh
rm -rf "$OUT/fit/ph"
find "$OUT/fit" -type f ! -name '*.txt' ! -name 'summary.json' -delete
find "$OUT" -type f | sort
