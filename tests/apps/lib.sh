# Shared by the end-to-end scripts in tests/apps: a scratch folder removed on exit, pass/fail
# counters, and the summary line whose exit status is the test's result.
#   source "$(dirname "$0")/lib.sh"   ...   finish
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passes=0
pass() { passes=$((passes + 1)); echo "ok   $1"; }
fail() { failures=$((failures + 1)); echo "FAIL $1"; }
finish() { echo "$passes passed, $failures failed"; [[ $failures -eq 0 ]]; }

# A 5 × 5 × 5 block of 'soft' tissue (h = 2 mm, E = 3 kPa) under gravity, its base layer held:
# the scripts' smallest scene; callers append their own sections.
block_scene() {
  cat <<TOML
[model]
spacing = 0.002
[[model.shape]]
kind = "box"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
label = "soft"
[materials.soft]
E = 3000.0
[gravity]
vector = [0.0, 0.0, -9.81]
[anchor.base]
kind = "halfspace"
point = [0.0, 0.0, 0.002]
normal = [0.0, 0.0, -1.0]
TOML
}
