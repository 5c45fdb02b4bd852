#!/usr/bin/env bash
# The finite-element cross-check at CI size (docs/VALIDATION.md, "Finite-element cross-check"):
# coarse FEniCSx references and 4 mm VoxBreast models, each error checked against its bound in
# tests/validation/fe_bounds.json. Fails when an error leaves its bound, when VoxBreast or the FE
# Newton solve does not converge (the driver refuses to compare then). Skips (77) only when
# python3-dolfinx is not installed (scripts/setup.sh installs it).
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/validation/fe_crosscheck_quick.sh REPO_ROOT
set -euo pipefail
root=${1:?usage: fe_crosscheck_quick.sh REPO_ROOT}
bin=${VOXBREAST_BIN:?set VOXBREAST_BIN}
if ! /usr/bin/python3 -c "import dolfinx" 2>/dev/null; then
  echo "fe_crosscheck_quick: python3-dolfinx is not installed (scripts/setup.sh)"; exit 77
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export OMP_NUM_THREADS=1
/usr/bin/python3 "$root/scripts/fe_reference/crosscheck.py" --quick --voxbreast "$bin" --out "$out" \
  --cases cube_sag,cube_sag_small,cube_sag_nu0499,hemisphere_sideways,confined_nu0499 \
  --spacings 4 --precisions double --bounds "$root/tests/validation/fe_bounds.json"
