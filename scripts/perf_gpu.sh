#!/usr/bin/env bash
# Step-time measurements on a GPU in one device call (~4 min on an H200): the volume,
# kernel and hyperelastic tests on the GPU first (volume_project and volume_pending rely on a
# last-work-group count across the device; the GPU runs the split force passes), then per-kernel
# profiles of the rows docs/PERFORMANCE.md reads: 36k linear, two-term Ogden with and without the
# volume constraint (the 20k target row), and 1.5M two-term Ogden, Heun, float.
# With a reference build (.device-pkgs/ref.tar.xz holding bin/voxbreast of another commit, made by
# `bash scripts/perf_gpu.sh ref BUILD_DIR` here) the same rows run with it too, interleaved with
# this build's, so that one call gives an A/B on one device.
# Launch-plan overrides the A/B rows also try (bench --plan; engine/sim/launch_plan.hpp):
#   force_split=1|2|4                work-items per element in Heun's force passes (GPU default 2
#                                    for hyperelastic models up to 98,304 elements)
#   --volume-predictor projection    the volume rows with Heun's predicted stage projected
#   stress_pair=0                    both element stresses of a Heun step in two launches
#   persistent=0|1                   Heun's step as one launch with grid barriers (NVIDIA default
#                                    for spring models up to 45,056 elements; the 36k rows run
#                                    the default and =0)
#   here:   cmake --build build --target voxbreast test_physics && bash scripts/gpu_run.sh prepare
#   device: bash scripts/perf_gpu.sh      (run tool, carry [".device-pkgs"]; writes $OUT/perf)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

if [[ "${1:-}" == ref ]]; then  # bundle a reference build's voxbreast next to the prepared one
  tar -C "${2:?usage: $0 ref BUILD_DIR}" -cJf .device-pkgs/ref.tar.xz --transform 's|^apps|bin|' apps/voxbreast
  exit
fi

out=${OUT:?run on the device machine, where \$OUT is the folder that comes back}/perf
mkdir -p "$out"
run() { bash scripts/gpu_run.sh run "$@"; }
ref=""
if [[ -f .device-pkgs/ref.tar.xz ]]; then
  ref=$(mktemp -d) && tar -C "$ref" -xJf .device-pkgs/ref.tar.xz && ref=$ref/bin/voxbreast
fi
bench=(bench --device gpu --quick --no-study --profile)
# name, binary, then bench arguments
# (all rows into one file: the device tool brings back few files)
row() {
  local name=$1 bin=$2; shift 2
  echo "== $name: $bin $*" | tee -a "$out/rows.txt"
  run "$bin" "${bench[@]}" "$@" --out "$(mktemp -d)" 2>&1 | tee -a "$out/rows.txt"
}
gpu_tests() {
  VOXBREAST_DEVICE=gpu run test_physics --gtest_filter='*VolumeKernels*:VolumeConstraint.*:*KernelForces*:*KernelSteps*:HyperelasticKernels.*:*Uniaxial*:*SimpleShear*:*Tension*:*PlateCompression*:*BiphasicKernels*:*RestOffsets*:*TorusContact*:*Relaxation*:*SetMaterials*:PersistentStep*:LanesStep.*' \
    2>&1 | grep -E '^\[ *(OK|FAILED|PASSED) *\]|Failure|pending vs' | tee "$out/gpu_tests.txt"
}

# `perf_gpu.sh target` (~7 min on an H200): only the 36k target rows (two-term Ogden + volume; --breast runs
# the breast phantom and the cube), three rounds interleaved with the reference build's, then the
# GPU tests.
if [[ "${1:-}" == target ]]; then
  for round in 1 2 3; do
    row "new_r$round" voxbreast --breast --sizes 33 --laws ogden --volume
    [[ -n "$ref" ]] && row "ref_r$round" "$ref" --breast --sizes 33 --laws ogden --volume
  done
  # the projection in one launch (volume_project) instead of two
  row breast_project1 voxbreast --breast --sizes 33 --laws ogden --volume --plan volume_launches=1
  gpu_tests
  grep -hE '^== |^(block|breast)(_volume)? +[0-9]+ elements|device alone|error' "$out/rows.txt" | tee "$out/summary.txt"
  exit
fi

gpu_tests

for round in 1 2; do
  row "36k_r$round" voxbreast --sizes 33 --laws linear ogden --volume
  # one launch per pass instead of the persistent step (kernels/persistent.cl)
  row "36k_launches_r$round" voxbreast --sizes 33 --laws linear ogden --volume --plan persistent=0
  # Heun's predicted stage projected instead of under the lagged pressure (docs/PERFORMANCE.md, "Volume projection forms")
  row "36k_projection_r$round" voxbreast --sizes 33 --laws ogden --volume --volume-predictor projection
  [[ -n "$ref" ]] && row "36k_ref_r$round" "$ref" --sizes 33 --laws linear ogden --volume
done
# the breast phantom at 3.2 mm (34,961 elements, a third of them moving) next to the cube
row 36k_breast voxbreast --breast --sizes 33 --laws linear neo-hookean ogden --volume
# both of Heun's element stresses in two launches instead of one (docs/PERFORMANCE.md, "Volume projection forms")
row 36k_breast_nopair voxbreast --breast --sizes 33 --laws ogden --volume --plan stress_pair=0
row 36k_split1 voxbreast --sizes 33 --laws ogden --volume --plan force_split=1
row 36k_split4 voxbreast --sizes 33 --laws ogden --volume --plan force_split=4
row 1.5M voxbreast --sizes 115 --laws ogden
[[ -n "$ref" ]] && row 1.5M_ref "$ref" --sizes 115 --laws ogden
grep -hE '^== |^(block|breast)(_volume)? +[0-9]+ elements' "$out/rows.txt" | tee "$out/summary.txt"
# PTX and build logs (registers, spills) of the 36k Ogden + volume program, as one archive
ptx=$(mktemp -d)
VOXBREAST_DUMP_KERNELS="$ptx/ptx" VOXBREAST_CL_OPTIONS=-cl-nv-verbose \
  run voxbreast bench --device gpu --quick --no-study --sizes 8 --laws ogden --volume --out "$ptx/run" >/dev/null 2>&1
tar -C "$ptx" -czf "$out/ptx.tar.gz" ptx
