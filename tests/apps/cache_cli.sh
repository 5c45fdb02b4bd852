#!/usr/bin/env bash
# The program cache from the command line: two processes filling an empty cache at once both
# succeed, a third run loads what they stored and ends in the same state to the last digit,
# `voxbreast cache` and `info` show the folder and its size, and `cache --clear` empties it.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/cache_cli.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"
export VOXBREAST_CACHE_DIR="$work/cache"

cat >"$work/cube.toml" <<'TOML'
[model]
spacing = 0.004
[[model.shape]]
kind = "box"
min = [0.0, 0.0, 0.0]
max = [0.024, 0.024, 0.024]
label = "soft"
[materials.soft]
law = "neo-hookean"
E = 3000.0
[anchor.base]
kind = "halfspace"
point = [0.0, 0.0, 0.002]
normal = [0.0, 0.0, -1.0]
[gravity]
vector = [0.0, 0.0, -9.81]
[stop]
equilibrium = 0.0
max_steps = 300
TOML

"$bin" simulate "$work/cube.toml" --out "$work/a" --quiet >"$work/a.txt" 2>&1 &
a=$!
"$bin" simulate "$work/cube.toml" --out "$work/b" --quiet >"$work/b.txt" 2>&1 &
b=$!
wait $a; ra=$?
wait $b; rb=$?
entries=$(find "$work/cache" -name '*.vbprog' | wc -l)
stray=$(find "$work/cache" -name '*.tmp.*' | wc -l)
if [[ $ra -eq 0 && $rb -eq 0 && $entries -ge 1 && $stray -eq 0 ]]; then
  pass "two processes filling an empty cache at once: both succeed, $entries entries, no temporary files"
else fail "concurrent fill (exit $ra, $rb; $entries entries, $stray temporary)"; cat "$work/a.txt" "$work/b.txt"; fi

before=$(find "$work/cache" -name '*.vbprog' -newer "$work/cube.toml" -printf '%T@ %p\n' | sort)
"$bin" simulate "$work/cube.toml" --out "$work/c" --quiet >"$work/c.txt" 2>&1; rc=$?
after=$(find "$work/cache" -name '*.vbprog' -newer "$work/cube.toml" -printf '%T@ %p\n' | sort)
field() { python3 -c "import json,sys; print(repr(json.load(open(sys.argv[1]))['max_displacement_m']))" "$1"; }
if [[ $rc -eq 0 && "$before" == "$after" && "$(field "$work/a/summary.json")" == "$(field "$work/c/summary.json")" \
      && "$(field "$work/b/summary.json")" == "$(field "$work/c/summary.json")" ]]; then
  pass "a run from the cache rewrites no entry and ends where the building runs did: $(field "$work/c/summary.json") m"
else fail "cache hit"; cat "$work/c.txt"; fi

if "$bin" cache >"$work/show.txt" 2>&1 && grep -q "$work/cache: $entries programs" "$work/show.txt" \
   && "$bin" info 2>&1 | grep -q "program cache: $work/cache"; then
  pass "voxbreast cache / info: $(cat "$work/show.txt")"
else fail "cache / info"; cat "$work/show.txt"; fi

if "$bin" cache --clear >"$work/clear.txt" 2>&1 && [[ $(find "$work/cache" -name '*.vbprog' | wc -l) -eq 0 ]] \
   && "$bin" cache | grep -q ": 0 programs"; then
  pass "voxbreast cache --clear: $(cat "$work/clear.txt")"
else fail "cache --clear"; cat "$work/clear.txt"; fi

finish
