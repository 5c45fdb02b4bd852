#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: install dependencies, build, run the whole suite.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${VOXBREAST_BUILD_DIR:-$root/build}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
# Tests run on the CPU OpenCL device unless told otherwise (CI has only PoCL).
export VOXBREAST_DEVICE=${VOXBREAST_DEVICE:-cpu}
# Built kernels are kept between test processes (and runs) in the build folder.
export VOXBREAST_CACHE_DIR=${VOXBREAST_CACHE_DIR:-$build/program-cache}
status=0
# Long validation studies and GPU-only checks are labelled and run apart (README, "Quick start").
(cd "$build" && ctest --output-on-failure --parallel "$(nproc)" --timeout 1200 -LE "slow|validation|gpu" -E "Study\.|Gpu\.") ||
  status=1
# The io and engine unit tests once more, built with ASan and UBSan (float-cast-overflow included)
# in a folder of their own: any sanitizer report fails the suite.
bash "$root/scripts/sanitize.sh" || status=1
exit $status
