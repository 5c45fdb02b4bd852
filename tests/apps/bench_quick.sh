#!/usr/bin/env bash
# Runs `voxbreast bench --quick` (the CI-sized speed/accuracy study) and checks its output.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/bench_quick.sh .
set -euo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" bench --quick --out "$work" --phantom "$root/data-samples/phantom/scene.toml"
/usr/bin/python3 "$root/tests/apps/check_bench.py" "$work"
