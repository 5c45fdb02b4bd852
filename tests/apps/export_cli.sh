#!/usr/bin/env bash
# voxbreast export --feb end to end: every sample scene in data-samples/ becomes a valid FEBio 4.0
# model (schema and mesh checks, tests/io/check_febio.py) whose node and hex counts are those the
# command reports; bad input fails with a one-line error and writes no file.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/export_cli.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"
check="$root/tests/io/check_febio.py"

while IFS= read -r scene; do
  name=${scene#"$root/data-samples/"}
  feb="$work/${name//\//_}.feb"
  if "$bin" export "$scene" --feb "$feb" >"$work/out.txt" 2>"$work/err.txt" \
     && /usr/bin/python3 "$check" "$feb" >"$work/check.txt" 2>&1; then
    counts=$(sed -n 's/.*: \([0-9]*\) nodes, \([0-9]*\) hex8 elements, \([0-9]*\) fixed.*/\1 \2 \3/p' "$work/out.txt")
    checked=$(sed -n 's/.*, \([0-9]*\) nodes, \([0-9]*\) hex8, \([0-9]*\) fixed.*/\1 \2 \3/p' "$work/check.txt")
    if [[ -n "$counts" && "$counts" == "$checked" ]]; then pass "$name: $(cat "$work/check.txt")"
    else fail "$name: reported '$counts', file has '$checked'"; fi
  else
    fail "$name"; cat "$work/out.txt" "$work/err.txt" "$work/check.txt" 2>/dev/null
  fi
done < <(grep -l '^\[model\]' "$root"/data-samples/*.toml "$root"/data-samples/*/*.toml)

# a model with no 2×2×2 block of elements has no hexahedron to write
cat >"$work/strand.toml" <<'TOML'
[model]
spacing = 0.002
[[model.shape]]
kind = "box"
min = [0.0, 0.0, 0.0]
max = [0.002, 0.002, 0.02]
label = "soft"
[materials.soft]
E = 3000.0
TOML
if ! "$bin" export "$work/strand.toml" --feb "$work/strand.feb" >/dev/null 2>"$work/strand.err" \
   && grep -q "^voxbreast: error:.*no complete dual cell" "$work/strand.err" && [[ ! -e "$work/strand.feb" ]]; then
  pass "a one-voxel strand: $(cat "$work/strand.err")"
else fail "strand"; cat "$work/strand.err"; fi

if ! "$bin" export "$work/missing.toml" --feb "$work/missing.feb" >/dev/null 2>"$work/missing.err" \
   && [[ $(wc -l <"$work/missing.err") -eq 1 && ! -e "$work/missing.feb" ]]; then
  pass "a missing scene: $(cat "$work/missing.err")"
else fail "missing scene"; cat "$work/missing.err"; fi

finish
