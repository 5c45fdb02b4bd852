#!/usr/bin/env bash
# End-to-end checks of voxbreast haptic and voxbreast fit-curve (docs/HAPTICS.md,
# docs/FIT_CURVE.md): the samples run and write their outputs; bad trajectories and curves fail
# with a one-line error naming the file and line, a non-zero exit, and no output file; a haptic
# press that folds the lattice warns once, says folded in its summary and still exits 0.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/force_feedback_cli.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"

# expect_error NAME PATTERN OUTFILE -- command...: non-zero exit, PATTERN in stderr, OUTFILE absent
expect_error() {
  local name=$1 pattern=$2 outfile=$3
  shift 4
  if "$@" >"$work/out.txt" 2>"$work/err.txt"; then fail "$name (exit 0)"; return; fi
  if ! grep -q "voxbreast: error: .*$pattern" "$work/err.txt"; then fail "$name (message)"; cat "$work/err.txt"; return; fi
  if [[ -e "$outfile" ]]; then fail "$name (wrote $outfile)"; return; fi
  pass "$name"
}

# --- haptic: the sample, half a second
scene=$root/data-samples/haptic/block.toml
if "$bin" haptic "$scene" --trajectory "$root/data-samples/haptic/press.csv" --seconds 0.5 --out "$work/haptic" -q \
     >"$work/haptic.txt" 2>&1 && python3 - "$work/haptic" <<'PY'
import csv, json, sys
s = json.load(open(sys.argv[1] + "/haptic_summary.json"))
assert not s["blown_up"], s["message"]
assert s["outputs"] > 200 and s["achieved_rate_hz"] > 300, s   # 1 kHz asked; CI machines are loaded
assert s["deformation_updates"] >= 1 and s["elements"] == 10164, s
rows = list(csv.DictReader(open(sys.argv[1] + "/haptic.csv")))
assert len(rows) == s["outputs"]
assert set(rows[0]) == {"time_s", "x_mm", "y_mm", "z_mm", "fx_n", "fy_n", "fz_n", "updates", "min_det_f"}, rows[0].keys()
assert s["fold_checks"] >= 1 and s["folded"] == (s["min_det_f"] <= 0) == (s["folded_checks"] > 0), s
assert float(rows[-1]["z_mm"]) < 44, rows[-1]            # the probe moved down the trajectory
assert all(float(r["fz_n"]) >= 0 for r in rows)         # the tissue only pushes the probe up
PY
then pass "haptic sample writes haptic.csv and haptic_summary.json"
else fail "haptic sample"; cat "$work/haptic.txt"; fi

# --- haptic: 8 mm deep with the 5 mm ball folds the lattice (docs/VALIDATION.md): one warning,
# folded in the summary, exit 0
printf 'time_s,x_mm,y_mm,z_mm\n0,22,22,44\n1,22,22,36\n' >"$work/deep.csv"
if "$bin" haptic "$scene" --trajectory "$work/deep.csv" --seconds 2.5 --out "$work/deep" -q \
     >"$work/deep.txt" 2>"$work/deep_err.txt" && python3 - "$work/deep" "$work/deep_err.txt" <<'PY'
import csv, json, sys
s = json.load(open(sys.argv[1] + "/haptic_summary.json"))
assert not s["blown_up"], s["message"]
assert s["folded"] and s["min_det_f"] <= 0 and s["folded_checks"] >= 1, s
assert 0 < s["first_fold_time_s"] <= s["wall_s"] and s["first_fold_update"] >= 1, s
rows = list(csv.DictReader(open(sys.argv[1] + "/haptic.csv")))
assert min(float(r["min_det_f"]) for r in rows) <= 0
err = open(sys.argv[2]).read()
assert err.count("voxbreast: warning: the lattice folded under the probe at t = ") == 1, err
PY
then pass "haptic: a folding press warns, says folded and exits 0"
else fail "haptic: folding press"; cat "$work/deep.txt" "$work/deep_err.txt"; fi

printf 'time_s,x_mm,y_mm,z_mm\n0,22,22,44\n0,22,22,40\n' >"$work/repeated.csv"
expect_error "haptic: times must increase" "time_s does not increase" "$work/h1/haptic.csv" -- \
  "$bin" haptic "$scene" --trajectory "$work/repeated.csv" --out "$work/h1"
printf 'time_s,x_mm,y_mm\n0,22,22\n' >"$work/columns.csv"
expect_error "haptic: trajectory header" "header" "$work/h2/haptic.csv" -- \
  "$bin" haptic "$scene" --trajectory "$work/columns.csv" --out "$work/h2"
expect_error "haptic: scene without a probe" "indenter" "$work/h3/haptic.csv" -- \
  "$bin" haptic "$root/data-samples/breast_phantom.toml" --trajectory "$root/data-samples/haptic/press.csv" --out "$work/h3"

# --- fit-curve: corrupt curves
cube=$root/data-samples/fit_curve/cube.toml
printf 'displacement_mm,force_n\n0,0\n1,0.02\n2,0.0x4\n' >"$work/corrupt.csv"
expect_error "fit-curve: corrupt number names file and line" "corrupt.csv:4" "$work/f1/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$work/corrupt.csv" --out "$work/f1"
printf 'displacement_mm,force_n\n0,0\n1\n' >"$work/short.csv"
expect_error "fit-curve: missing field" "1 fields" "$work/f2/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$work/short.csv" --out "$work/f2"
printf '\x00\x01binary' >"$work/binary.csv"
expect_error "fit-curve: not a CSV" "header" "$work/f3/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$work/binary.csv" --out "$work/f3"
printf 'displacement_mm,force_n\n1,0.02\n1,0.03\n' >"$work/twice.csv"
expect_error "fit-curve: displacement twice" "given twice" "$work/f4/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$work/twice.csv" --out "$work/f4"
expect_error "fit-curve: parameter of another law" "mu is an Ogden parameter" "$work/f5/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$root/data-samples/fit_curve/measured.csv" --params mu --out "$work/f5"
expect_error "fit-curve: missing curve file" "cannot open" "$work/f6/fit_curve.json" -- \
  "$bin" fit-curve "$cube" --curve "$work/nonexistent.csv" --out "$work/f6"

finish
