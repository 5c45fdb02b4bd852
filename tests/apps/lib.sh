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

# Starts `$bin SUBCOMMAND ARGS...` (view, serve) in the background, killed on exit, and sets $url
# from the first URL it prints, waiting at most TENTHS tenths of a second; prints its log and
# returns 1 when it exits or prints none.   start_server TENTHS SUBCOMMAND ARGS...
servers=()
trap 'for p in "${servers[@]}"; do kill "$p" 2>/dev/null; done; rm -rf "$work"' EXIT
start_server() {
  local tenths=$1 log=$work/$2-$RANDOM.log
  shift
  "$bin" "$@" >"$log" 2>&1 &
  servers+=($!)
  url=""
  for _ in $(seq "$tenths"); do
    url=$(grep -o 'http://[^ ]*' "$log" | head -1)
    [[ -n $url ]] && return 0
    kill -0 "${servers[-1]}" 2>/dev/null || break
    sleep 0.1
  done
  cat "$log"
  return 1
}

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
