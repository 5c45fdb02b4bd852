#!/usr/bin/env bash
# Session 34's one device call (run tool, carry [".device-pkgs"]): after the simulator and DICOM
# files were split (code moved, not changed), the GPU tests and step times of perf_gpu.sh against
# the reference build c4011a3 (.device-pkgs/ref.tar.xz), then gpu_fit.sh's fit timings. Only the
# text results come back (the phantom and the fits' NIfTI maps are removed).
set -uo pipefail
cd "$(dirname "$0")/../../.."
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader >"$OUT/gpu.txt" 2>&1
bash scripts/perf_gpu.sh
bash scripts/gpu_fit.sh
rm -rf "$OUT/fit/ph"
find "$OUT/fit" -type f ! -name '*.txt' ! -name 'summary.json' -delete
find "$OUT" -type f | sort
