#!/usr/bin/env bash
# The io and engine unit tests (test_io, test_engine: no long OpenCL runs) built with ASan and
# UBSan (float-cast-overflow included) in a folder of their own, and run. Any sanitizer report
# fails the test it happens in, and this script exits non-zero.
#
# Usage: bash scripts/sanitize.sh            (from any folder; after scripts/setup.sh)
# Environment: VOXBREAST_SANITIZE_DIR   build folder (default build-sanitize at the repository root)
#              VOXBREAST_SANITIZE_TESTS test binaries to build and run (default "test_io test_engine")
# ccache is used when installed: the second build onwards recompiles only what changed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${VOXBREAST_SANITIZE_DIR:-$root/build-sanitize}
tests=${VOXBREAST_SANITIZE_TESTS:-test_io test_engine}
# -O1 with line tables: reports name file and line. (-O0 builds in 6.5 min instead of about 8 on
# 2 cores, but test_engine then runs 7 min instead of about 1.)
options=(-DVOXBREAST_SANITIZE=ON -DVOXBREAST_MPI=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1")
command -v ninja >/dev/null && options+=(-G Ninja)
command -v ccache >/dev/null && options+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S "$root" -B "$build" "${options[@]}" >/dev/null
# shellcheck disable=SC2086
cmake --build "$build" --parallel "$(nproc)" --target $tests
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
status=0
for t in $tests; do
  echo "sanitize.sh: $t"
  "$build/tests/$t" --gtest_brief=1 || status=1
done
exit $status
