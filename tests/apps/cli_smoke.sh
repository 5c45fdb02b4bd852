#!/usr/bin/env bash
# End-to-end checks of the voxbreast command line: the bundled sample runs and writes its
# outputs; each kind of bad input fails with a one-line error, a non-zero exit, and no result.h5.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/cli_smoke.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"

# --- info
if "$bin" info >"$work/info.txt" 2>&1 && grep -q "fp64" "$work/info.txt"; then pass "info lists devices"; else fail "info"; cat "$work/info.txt"; fi

# --- the bundled sample
if "$bin" simulate "$root/data-samples/breast_phantom.toml" --out "$work/sample" --quiet >"$work/sample.txt" 2>&1 \
   && grep -q "wrote .*summary.json" "$work/sample.txt" && grep -q "wrote .*result.h5" "$work/sample.txt" \
   && python3 - "$work/sample/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["converged"] is True, s["stop_reason"]
assert s["elements"] > 5000 and s["connections"] > 10 * s["elements"]
t = s["tracked"]["tumour_centre"]["displacement_m"]
nipple = s["tracked"]["nipple"]["displacement_m"]
assert t[1] < -0.0005, t  # prone: the tumour moves anteriorly (−y, away from the chest wall)
assert nipple[1] < t[1], (nipple, t)  # tissue far from the chest wall moves more
m = s["mesh_outputs"]  # the sample asks for output.surfaces
assert m["surface_triangles"] > 2 * 1000 and m["surface_vertices"] > 1000, m
import os
for f in m["files"]:
    assert os.path.getsize(os.path.join(os.path.dirname(sys.argv[1]), f)) > 1000, f
PY
then pass "sample scene converges, tumour moves anteriorly, outputs and meshes written"
else fail "sample scene"; cat "$work/sample.txt"; fi
h5dump -H "$work/sample/result.h5" >"$work/h5.txt" 2>&1
if grep -q '"displacement_m"' "$work/h5.txt"; then pass "result.h5 readable"; else fail "result.h5"; fi

# --- whole output folders (docs/OUTPUTS.md): a second writer is refused while the folder is locked;
# a rerun removes a killed run's temporary file and records its files in the manifest; a folder
# holding someone else's summary.json is refused before computing and left as it was.
touch "$work/sample/.result.h5.tmp-999999-0"
python3 -c 'import fcntl, os, sys, time
fd = os.open(sys.argv[1], os.O_RDONLY); fcntl.flock(fd, fcntl.LOCK_EX); print("held", flush=True); time.sleep(60)' \
  "$work/sample" >"$work/lock.txt" & holder=$!
for _ in $(seq 50); do grep -q held "$work/lock.txt" 2>/dev/null && break; sleep 0.1; done
if ! "$bin" simulate "$root/data-samples/breast_phantom.toml" --out "$work/sample" --quiet >/dev/null 2>"$work/locked.err" \
   && grep -q "another VoxBreast run is writing to this output folder" "$work/locked.err"
then pass "a second run into a locked output folder is refused"
else fail "lock"; cat "$work/locked.err"; fi
kill "$holder"; wait "$holder" 2>/dev/null
if "$bin" simulate "$root/data-samples/breast_phantom.toml" --out "$work/sample" --quiet >/dev/null 2>&1 \
   && [ ! -e "$work/sample/.result.h5.tmp-999999-0" ] && python3 - "$work/sample" <<'PY'
import json, os, sys
d = sys.argv[1]
m = json.load(open(os.path.join(d, ".voxbreast-manifest.json")))["runs"]["simulate"]
assert {"summary.json", "metrics.csv", "result.h5", "surface.vtp"} <= set(m), m
assert sorted(m) == sorted(e for e in os.listdir(d) if not e.startswith(".")), (m, os.listdir(d))
PY
then pass "a rerun removes a killed run's temporary file and lists every output in the manifest"
else fail "rerun manifest"; fi
mkdir -p "$work/foreign" && echo mine >"$work/foreign/summary.json"
if ! "$bin" simulate "$root/data-samples/breast_phantom.toml" --out "$work/foreign" --quiet >/dev/null 2>"$work/foreign.err" \
   && grep -q "holds 'summary.json', which no earlier VoxBreast run recorded writing" "$work/foreign.err" \
   && [ "$(cat "$work/foreign/summary.json")" = mine ] && [ "$(ls -A "$work/foreign")" = summary.json ]
then pass "someone else's summary.json stops the run before it computes"
else fail "foreign summary.json"; cat "$work/foreign.err"; fi

# --- the main job: the bundled phantom CT (DICOM) to DVF, warped CT and summary
if "$bin" simulate "$root/data-samples/phantom/scene_dicom.toml" --out "$work/ct" --quiet >"$work/ct.txt" 2>&1 \
   && /usr/bin/python3 - "$work/ct" <<'PY'
import json, sys, nibabel as nib, numpy as np
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
assert s["converged"], s["stop_reason"]
dvf = nib.load(d + "/dvf.nii.gz")
assert dvf.shape[3:] == (1, 3) and dvf.header.get_intent()[0] == "displacement vector", dvf.header.get_intent()
u = np.asarray(dvf.dataobj)
assert np.abs(u).max() > 0.5, "a prone breast moves by more than half a millimetre"  # mm
w = nib.load(d + "/warped_ct.nii.gz")
assert w.shape == dvf.shape[:3]
t = s["tracked"]["tumour_1"]["displacement_m"]
assert t[1] < 0, t  # prone: anteriorly
# The main job starts from the unloaded breast, estimated from the supine CT, and says so.
r = s["reference_state"]
assert r["converged"] and r["ct_posture"] == "supine" and r["iterations"] >= 2, r
assert s["positioning"]["tumour"]["displacement_norm_m"] > 5e-4, s["positioning"]["tumour"]
out = open(d + "/../ct.txt").read()
assert "from the CT (supine) to prone, simulated from the unloaded state" in out, out
PY
then pass "CT phantom (DICOM) → summary, DVF, warped CT, supine → prone from the unloaded state"
else fail "CT phantom"; cat "$work/ct.txt"; fi
# The same CT as NIfTI must give the same result as the DICOM series (the main job's scene with
# the NIfTI CT in place of the series).
ph="$root/data-samples/phantom"
sed -e "s|^image = \"dicom\"|image = \"$ph/ct.nii.gz\"|" -e "s|^labels = \"labels.nii.gz\"|labels = \"$ph/labels.nii.gz\"|" \
  "$ph/scene_dicom.toml" >"$work/scene_nifti.toml"
if "$bin" simulate "$work/scene_nifti.toml" --out "$work/ct_nifti" --quiet >/dev/null 2>&1 \
   && python3 - "$work/ct/summary.json" "$work/ct_nifti/summary.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert a["elements"] == b["elements"] and a["steps"] == b["steps"], (a["elements"], b["elements"])
ua, ub = a["tracked"]["tumour_1"]["displacement_m"], b["tracked"]["tumour_1"]["displacement_m"]
assert max(abs(x - y) for x, y in zip(ua, ub)) < 1e-9, (ua, ub)
PY
then pass "NIfTI and DICOM inputs give the same result"
else fail "NIfTI vs DICOM"; fi
if dcmdump "$work/ct/warped_ct_dicom/CT00001.dcm" >/dev/null 2>&1; then pass "warped CT DICOM readable by dcmdump"; else fail "warped CT DICOM"; fi
# A rerun into the same folder replaces its own warped series whole (a new series UID, no
# leftovers); a file of someone else's in that folder stops the rerun before it computes.
series_uid() { dcmdump +P 0020,000e "$1/CT00001.dcm" 2>/dev/null; }  # of the series in folder $1
first_uid=$(series_uid "$work/ct/warped_ct_dicom"); slices=$(ls "$work/ct/warped_ct_dicom" | wc -l)
if "$bin" simulate "$root/data-samples/phantom/scene_dicom.toml" --out "$work/ct" --quiet >/dev/null 2>&1 \
   && [ -n "$first_uid" ] && [ "$(series_uid "$work/ct/warped_ct_dicom")" != "$first_uid" ] \
   && [ "$(ls "$work/ct/warped_ct_dicom" | wc -l)" = "$slices" ] && [ -z "$(ls -A "$work/ct" | grep '^\.' | grep -v '^\.voxbreast-manifest\.json$')" ]
then pass "a rerun into the same folder replaces its warped CT series"
else fail "rerun replaces the warped series"; fi
h5_inode=$(stat -c %i "$work/ct/result.h5") && touch "$work/ct/warped_ct_dicom/notes.txt"  # a rewrite is a new inode
if ! "$bin" simulate "$root/data-samples/phantom/scene_dicom.toml" --out "$work/ct" --quiet >/dev/null 2>"$work/ct_foreign.err" \
   && grep -q "holds 'notes.txt', which is not a slice" "$work/ct_foreign.err" \
   && [ "$(stat -c %i "$work/ct/result.h5")" = "$h5_inode" ]
then pass "a foreign file in warped_ct_dicom/ stops the rerun before any output is replaced"
else fail "foreign file in the warped series folder"; cat "$work/ct_foreign.err"; fi

# --- voxbreast phantom: a rerun with another seed replaces all four outputs, its DICOM series whole;
# a foreign file in dicom/ stops it before any file is replaced.
ph="$work/phantom"
if "$bin" phantom --out "$ph" --spacing 6 --seed 1 >/dev/null 2>&1 && cp "$ph/ct.nii.gz" "$work/ph_seed1.nii.gz" \
   && uid1=$(series_uid "$ph/dicom") && [ -n "$uid1" ] \
   && "$bin" phantom --out "$ph" --spacing 6 --seed 2 >/dev/null 2>&1 \
   && ! cmp -s "$ph/ct.nii.gz" "$work/ph_seed1.nii.gz" && [ "$(series_uid "$ph/dicom")" != "$uid1" ] \
   && /usr/bin/python3 - "$ph" <<'PY'
import sys, glob, numpy as np, nibabel as nib, pydicom
d = sys.argv[1]
ct = np.asarray(nib.load(d + "/ct.nii.gz").dataobj)
files = sorted(glob.glob(d + "/dicom/*.dcm"))
assert len(files) == ct.shape[2], (len(files), ct.shape)
s = pydicom.dcmread(files[0])
assert np.array_equal(s.pixel_array.T * float(s.RescaleSlope) + float(s.RescaleIntercept), ct[:, :, 0]), "dicom/ is seed 2's CT"
PY
then pass "phantom rerun into its folder replaces the CT, labels and DICOM series"
else fail "phantom rerun"; fi
# The phantom's DICOM series is deterministic: the same phantom gives byte-identical files.
if "$bin" phantom --out "$work/phantom_again" --spacing 6 --seed 2 >/dev/null 2>&1 \
   && diff -r "$ph/dicom" "$work/phantom_again/dicom" >/dev/null
then pass "phantom DICOM series is the same, UIDs included, on every run"
else fail "phantom DICOM determinism"; fi
cp "$ph/ct.nii.gz" "$work/ph_seed2.nii.gz" && touch "$ph/dicom/notes.txt"
if ! "$bin" phantom --out "$ph" --spacing 6 --seed 3 >/dev/null 2>"$work/ph_foreign.err" \
   && grep -q "holds 'notes.txt'" "$work/ph_foreign.err" && cmp -s "$ph/ct.nii.gz" "$work/ph_seed2.nii.gz"
then pass "phantom refuses a foreign file in dicom/ before replacing anything"
else fail "phantom with a foreign file in dicom/"; cat "$work/ph_foreign.err"; fi

# --- a misused command line: one line in the form of every error, naming the option and the help, exit 2
"$bin" simulate "$root/data-samples/breast_phantom.toml" --out "$work/usage" --bogus >"$work/usage.out" 2>"$work/usage.err"
rc=$?
if [ "$rc" = 2 ] && [ "$(wc -l <"$work/usage.err")" = 1 ] && [ ! -s "$work/usage.out" ] && [ ! -e "$work/usage" ] \
   && grep -q "^voxbreast: error: .*--bogus (see 'voxbreast simulate --help')$" "$work/usage.err"
then pass "usage error: $(cat "$work/usage.err")"
else fail "usage error (rc $rc)"; cat "$work/usage.out" "$work/usage.err"; fi

# --- the positioning sample: the phantom prone in a two-ring device (docs/POSITIONING.md)
if "$bin" simulate "$root/data-samples/phantom/scene_device.toml" --out "$work/device" --quiet >"$work/device.txt" 2>&1 \
   && grep -q "wrote .*metrics.csv" "$work/device.txt" && python3 - "$work/device" <<'PY'
import csv, json, os, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
assert s["converged"], s["stop_reason"]
tori = s["immobilisation_device"]["tori"]
assert [t["name"] for t in tori] == ["base_ring", "front_ring"], tori
for t in tori:
    assert t["contact_elements"] > 10 and t["normal_force_sum_n"] > 0.1, t
    assert t["max_penetration_during_run_m"] <= 1e-3 * 0.004, t  # the stated tolerance, 0.001·h
p = s["positioning"]
assert p["tumour"]["tissue"] == "tumour" and p["tumour"]["elements"] > 10, p["tumour"]
assert p["tumour"]["displacement_m"][1] < 0, p["tumour"]  # prone: anteriorly
assert p["tumour"]["final_target_distance_m"] is not None
assert p["chest_wall"]["anchor"] == "chest" and p["chest_wall"]["tumour_distance_final_m"] > p["chest_wall"]["tumour_distance_rest_m"]
rows = list(csv.DictReader(open(d + "/metrics.csv")))
assert len(rows) == 1 and float(rows[0]["base_ring_normal_force_sum_n"]) > 0.1, rows
for f in ("device_base_ring.vtp", "device_base_ring.stl", "device_front_ring.vtp", "surface.vtp", "surface_unloaded.vtp"):
    assert f in s["mesh_outputs"]["files"] and os.path.getsize(os.path.join(d, f)) > 1000, f
# the unloaded reference state (CT supine): within its tolerance, and supine gravity undone
r = s["reference_state"]
assert r["converged"] and r["residual_max_m"] <= 1e-5 and r["max_rest_offset_m"] > 5e-4, r
# reproducibility: the same angles with and without the device; the device holds the tumour better
q = p["reproducibility"]
assert len(q["runs"]) == 2 * q["perturbations"] and all(run["converged"] for run in q["runs"]), q["runs"]
assert q["with_device"]["std_m"] < q["without_device"]["std_m"], (q["with_device"], q["without_device"])
assert q["without_device"]["std_m"] > 1e-3, q["without_device"]  # ±1° turns move the tumour by mm
assert abs(float(rows[0]["tumour_spread_std_device_mm"]) - 1e3 * q["with_device"]["std_m"]) < 1e-6, rows[0]
assert len(list(csv.DictReader(open(d + "/reproducibility.csv")))) == 2 * q["perturbations"]
PY
then pass "positioning sample: converges, rings in contact within tolerance, reference state, device reduces the tumour spread, metrics.csv and device meshes"
else fail "positioning sample"; cat "$work/device.txt"; fi

# The same sample under dynamic relaxation: every perturbed posture converges (the posed chest
# wall's rigid turn once starved its adaptive damping: 6 of 8 ran to max_steps), to the tumour
# positions of Heun's runs within 0.01 mm.
sample=$(cd "$root/data-samples/phantom" && pwd)  # the scene's CT paths, absolute from $work
sed -e 's/^integrator = "heun"/integrator = "relaxation"/' -e "s|= \"ct.nii.gz\"|= \"$sample/ct.nii.gz\"|" \
    -e "s|= \"labels.nii.gz\"|= \"$sample/labels.nii.gz\"|" -e 's/^surfaces = true/surfaces = false/' \
    "$root/data-samples/phantom/scene_device.toml" >"$work/device_relax.toml"
if grep -q '^integrator = "relaxation"' "$work/device_relax.toml" \
   && "$bin" simulate "$work/device_relax.toml" --out "$work/device_relax" --quiet >/dev/null 2>"$work/device_relax.err" \
   && python3 - "$work/device/summary.json" "$work/device_relax/summary.json" <<'PY'
import json, sys
heun, relax = (json.load(open(p)) for p in sys.argv[1:3])
assert relax["converged"], relax["stop_reason"]
a, b = (s["positioning"]["reproducibility"]["runs"] for s in (heun, relax))
assert len(a) == len(b) == 8, (len(a), len(b))
for x, y in zip(a, b):
    assert y["converged"] and y["steps"] < x["steps"], (x, y)
    assert max(abs(p - q) for p, q in zip(x["tumour_centroid_m"], y["tumour_centroid_m"])) < 1e-5, (x, y)
PY
then pass "positioning sample under relaxation: all 8 perturbed postures converge, in fewer steps, where Heun's land"
else fail "positioning sample under relaxation"; cat "$work/device_relax.err"; fi

# --- bad input: each must fail with one 'voxbreast: error:' line naming the problem, and no result.h5
scene() {  # base scene: a small block on a held base
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
[stop]
max_steps = 2000
TOML
}
expect_error() {  # name, expected text, scene text, [output folder]
  local name=$1 expected=$2 text=$3
  local dir=${4:-$work/$name}
  printf '%s\n' "$text" >"$work/$name.toml"
  "$bin" simulate "$work/$name.toml" --out "$dir" --quiet >"$work/$name.out" 2>"$work/$name.err"
  local rc=$?
  local lines
  lines=$(wc -l <"$work/$name.err")
  # The output folder did not exist before: a failed run removes it again (io/atomic_file.hpp, OutputDir).
  if [[ $rc -ne 0 && $lines -eq 1 ]] && grep -q "^voxbreast: error:.*$expected" "$work/$name.err" && [[ ! -e "$dir" ]]; then
    pass "$name: $(cat "$work/$name.err")"
  else
    fail "$name (rc $rc, $lines lines, expected '$expected')"; cat "$work/$name.err"
  fi
}

expect_error typo "materials.soft.Ee" "$(scene | sed 's/^E = 3000.0/Ee = 3000.0/')"
expect_error negative_modulus "materials.soft.E" "$(scene | sed 's/^E = 3000.0/E = -3000.0/')"
expect_error zero_spacing "model.spacing" "$(scene | sed 's/^spacing = 0.002/spacing = 0.0/')"
expect_error anchor_holds_nothing "anchor 'base' holds no element" "$(scene | sed 's/^point = \[0.0, 0.0, 0.002\]/point = [0.0, 0.0, -1.0]/')"
expect_error no_elements "no elements" "$(scene | sed 's/^max = \[0.01, 0.01, 0.01\]/max = [0.0005, 0.0005, 0.0005]/')"
expect_error unstable "unstable at step" "$(scene; printf '[solver]\nintegrator = "symplectic_euler"\ndt = 0.01\n')"
expect_error unwritable_output "cannot write to output folder" "$(scene)" /proc/voxbreast-not-writable
expect_error missing_material "soft" "$(scene | sed 's/^\[materials.soft\]/[materials.other]/')"
expect_error torus_tube_too_big "toml:22 key 'device.torus\[0\].minor_radius'" "$(scene; printf '[[device.torus]]\ncenter = [0.005, 0.005, 0.0]\naxis = [0.0, 0.0, 1.0]\nmajor_radius = 0.01\nminor_radius = 0.01\n')"

# A modulus written in kPa where pascals belong runs, with a warning on stderr and in summary.json
scene | sed 's/^E = 3000.0/E = 3.0/; /^\[gravity\]/,+1d' >"$work/kpa.toml"
if "$bin" simulate "$work/kpa.toml" --out "$work/kpa" --quiet >/dev/null 2>"$work/kpa.err" &&
   grep -q "^voxbreast: warning: materials.soft.E = 3 Pa .*(3 kPa is 3000)" "$work/kpa.err" &&
   grep -q "materials.soft.E = 3 Pa" "$work/kpa/summary.json"; then
  pass "modulus in kPa: $(cat "$work/kpa.err")"
else fail "modulus in kPa warning"; cat "$work/kpa.err"; fi

# Hyperelastic tissue carries the mass of the hull of its element centres (summary.json model); a
# one-voxel sheet has no elastic volume: its elements get a floor of 1/8 voxel, with a warning
{ scene | sed 's/^E = 3000.0/E = 3000.0\nlaw = "neo-hookean"\nnu = 0.45/; /^\[gravity\]/,+1d'
  printf '[[model.shape]]\nkind = "box"\nmin = [0.0, 0.0, 0.012]\nmax = [0.01, 0.01, 0.014]\nlabel = "sheet"\n'
  printf '[materials.sheet]\nE = 3000.0\nlaw = "neo-hookean"\nnu = 0.45\n'; } >"$work/sheet.toml"
if "$bin" simulate "$work/sheet.toml" --out "$work/sheet" --quiet >/dev/null 2>"$work/sheet.err" &&
   grep -q "^voxbreast: warning: tissue 'sheet' (hyperelastic): 25 of its 25 elements have no complete dual cell" "$work/sheet.err" &&
   grep -q "^voxbreast: warning: tissue 'sheet' (hyperelastic) carries .* 88% less than its voxels" "$work/sheet.err" &&
   ! grep -q "tissue 'soft'" "$work/sheet.err" &&
   python3 - "$work/sheet/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
m, v = s["model"], 0.002 ** 3 * 1000
assert abs(m["total_mass_kg"] - (4 ** 3 + 25 / 8) * v) < 1e-12, m  # the block's hull (4 spacings), the sheet's floor
assert abs(m["voxel_mass_kg"] - (125 + 25) * v) < 1e-12, m
assert abs(m["hull_mass_kg"] - 4 ** 3 * v) < 1e-12, m
assert m["tissues"]["sheet"]["floored_elements"] == 25 and m["tissues"]["soft"]["body"] == "hull", m
assert len(s["warnings"]) == 2, s["warnings"]
PY
then pass "hull masses in summary.json; one-voxel sheet: $(head -1 "$work/sheet.err")"
else fail "hull masses and one-voxel sheet warning"; cat "$work/sheet.err"; fi
# simulate --set: one value by dotted key, checked as sweep --vary checks it
scene >"$work/set.toml"
if "$bin" simulate "$work/set.toml" --out "$work/set" --quiet --set materials.soft.E=6000 --set +solver.integrator=relaxation \
     >/dev/null 2>&1 && h5dump -a /scene_toml "$work/set/result.h5" | grep -q 'E = 6000' \
   && h5dump -a /scene_toml "$work/set/result.h5" | grep -q 'integrator = .relaxation'
then pass "--set changes the scene the run uses (result.h5 keeps the edited text)"
else fail "--set"; fi
for bad in "materials.soft.Ee=1|did you mean 'E'" "materials.soft.E=-1|materials.soft.E" "materials.soft.E|--set materials.soft.E: expected KEY=VALUE"; do
  if ! "$bin" simulate "$work/set.toml" --out "$work/set_bad" --quiet --set "${bad%%|*}" >/dev/null 2>"$work/set_bad.err" \
     && [[ $(wc -l <"$work/set_bad.err") -eq 1 ]] && grep -q "^voxbreast: error:.*${bad#*|}" "$work/set_bad.err" && [[ ! -e "$work/set_bad" ]]
  then pass "--set ${bad%%|*}: $(cat "$work/set_bad.err")"
  else fail "--set ${bad%%|*}"; cat "$work/set_bad.err"; fi
done

# A corrupt CT: the phantom scene with a truncated ct.nii.gz
mkdir -p "$work/corrupt" && cp "$root/data-samples/phantom/labels.nii.gz" "$root/data-samples/phantom/scene.toml" "$work/corrupt/"
head -c 2000 "$root/data-samples/phantom/ct.nii.gz" >"$work/corrupt/ct.nii.gz"
if ! "$bin" simulate "$work/corrupt/scene.toml" --out "$work/corrupt/out" --quiet 2>"$work/corrupt.err" \
   && grep -q "^voxbreast: error:.*ct.nii.gz" "$work/corrupt.err" && [[ ! -e "$work/corrupt/out" ]]; then
  pass "truncated CT: $(cat "$work/corrupt.err")"
else fail "truncated CT"; cat "$work/corrupt.err"; fi

# --- voxbreast probe: settle under gravity, then a line of 3 presses (docs/PROBING.md)
{ scene | sed 's/^max = \[0.01, 0.01, 0.01\]/max = [0.016, 0.012, 0.01]/'
  printf '[solver]\nintegrator = "relaxation"\n[[indenter]]\nkind = "capsule"\nradius = 0.003\nlength = 0.004\naxis = [0, 1, 0]\n'
  printf '[probe]\nfrom = [0.003, 0.004, 0.05]\nto = [0.013, 0.004, 0.05]\npresses = 3\ndepth = 0.001\nsteps = 2\nat_force = [0.005]\n'
} >"$work/probe.toml"
if "$bin" probe "$work/probe.toml" --out "$work/probe" --quiet >"$work/probe.txt" 2>&1 && python3 - "$work/probe" <<'PY'
import csv, json, sys
d = sys.argv[1]
s = json.load(open(d + "/probe_summary.json"))
assert s["settle"]["converged"] and s["settle"]["max_displacement_mm"] > 0, s["settle"]
assert s["unconverged_increments"] == 0 and len(s["presses"]) == 3, s
curves = list(csv.DictReader(open(d + "/probe_curves.csv")))
assert len(curves) == 3 * 3, len(curves)
assert all(float(r["press_force_n"]) > 0 for r in curves if float(r["depth_mm"]) > 0), curves
profile = list(csv.DictReader(open(d + "/probe_profile.csv")))
assert [r["press"] for r in profile] == ["1", "2", "3"] and "depth_at_0.005N_mm" in profile[0], profile
assert all(float(r["contact_area_mm2"]) > 0 for r in profile), profile
PY
then pass "probe: settles, 3 presses, curves, profile and summary"
else fail "probe"; cat "$work/probe.txt"; fi
scene >"$work/noprobe.toml"
if ! "$bin" probe "$work/noprobe.toml" --out "$work/noprobe" --quiet 2>"$work/noprobe.err" \
   && grep -q "^voxbreast: error:.*no \[probe\] section" "$work/noprobe.err"; then
  pass "probe without [probe]: $(cat "$work/noprobe.err")"
else fail "probe without [probe]"; cat "$work/noprobe.err"; fi

finish
