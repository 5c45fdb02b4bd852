#!/usr/bin/env bash
# Session 32, device call 1: relaxation's Rayleigh-quotient rule on the H200 (the relaxation tests,
# and the device sample under relaxation against Heun, with its 8 perturbed postures).
set -uo pipefail
run() { bash scripts/gpu_run.sh run "$@"; }
run clinfo -l
VOXBREAST_DEVICE=gpu run test_physics --gtest_filter='Relaxation*' 2>&1 | grep -E "steps|OK|FAILED|PASSED"
sample=$(pwd)/data-samples/phantom
sed -e 's/^integrator = "heun"/integrator = "relaxation"/' -e "s|= \"ct.nii.gz\"|= \"$sample/ct.nii.gz\"|" \
    -e "s|= \"labels.nii.gz\"|= \"$sample/labels.nii.gz\"|" -e 's/^surfaces = true/surfaces = false/' \
    "$sample/scene_device.toml" >/tmp/device_relax.toml
for name in heun relax; do
  scene=$sample/scene_device.toml; [[ $name == relax ]] && scene=/tmp/device_relax.toml
  /usr/bin/time -f "$name wall %e s" bash scripts/gpu_run.sh run voxbreast simulate "$scene" --device gpu --out "$OUT/$name" --quiet 2>&1 | tail -4
done
