#!/usr/bin/env bash
# Session 35's device call: a fit's kept simulator (Simulator::set_materials) on the H200.
# 1. GPU tests: SetMaterials (a simulator given new moduli steps as a new one, to the bit), the
#    one-launch step and relaxation (dt is now set in one place), the kernels against the host.
# 2. gpu_fit.sh (sequential and batched Jacobians; its test_fit run includes ForwardModel*) with
#    this build, then with the reference b556f39 (.device-pkgs/ref.tar.xz), then this build again.
# Text results only.
set -uo pipefail
cd "$(dirname "$0")/../../.."
ref=$(mktemp -d) && tar -C "$ref" -xJf .device-pkgs/ref.tar.xz
VOXBREAST_DEVICE=gpu timeout 200 bash scripts/gpu_run.sh run test_physics \
  --gtest_filter='*SetMaterials*:PersistentStep.*:*Relaxation*:*KernelSteps*:*TimeStep*:*UniformPath*' 2>&1 |
  grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure' >"$OUT/gpu_tests.txt"
tail -n 2 "$OUT/gpu_tests.txt"
fit_round() {  # name, then the environment for gpu_fit.sh
  local name=$1; shift
  env OUT="$OUT/$name" "$@" timeout 150 bash scripts/gpu_fit.sh >/dev/null 2>&1
  rm -rf "$OUT/$name/fit/ph"
  find "$OUT/$name/fit" -type f ! -name '*.txt' ! -name 'summary.json' -delete
  grep -E '^== |jacobian_timing|wall_time' "$OUT/$name/fit/timing.txt"
}
fit_round new1
bash scripts/gpu_run.sh run bash -c "$(declare -f fit_round); fit_round ref VOXBREAST_BIN=$ref/bin/voxbreast DEVICE=gpu"
fit_round new2
find "$OUT" -type f | sort
