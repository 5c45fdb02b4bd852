#!/usr/bin/env bash
# RTSTRUCT in and out, checked with tools VoxBreast did not write: dciodvfy (dicom3tools) finds no
# error, pydicom reads the references back, and `plastimatch convert` rasterises the contours to
# the same label maps. The phantom's rtstruct.dcm drives a simulation instead of its label map
# (same model), whose warped_structures.dcm must match warped_labels.nii.gz. Bad structures fail
# with one line naming the ROI. Exit 77 (skipped) when a tool is missing.
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/rtstruct_cli.sh .
set -uo pipefail
root=${1:?source dir}
bin=${VOXBREAST_BIN:?path to voxbreast}
for tool in dciodvfy plastimatch; do
  command -v "$tool" >/dev/null || { echo "skipped: $tool is not installed (scripts/setup.sh)"; exit 77; }
done
/usr/bin/python3 -c 'import pydicom, nibabel' 2>/dev/null || { echo "skipped: pydicom or nibabel missing"; exit 77; }
source "$(dirname "$0")/lib.sh"

# dciodvfy prints "Error - ..." lines for violations of the IOD; warnings are allowed.
dicom_valid() {
  dciodvfy "$1" >"$work/dciodvfy.txt" 2>&1
  if grep -q '^Error' "$work/dciodvfy.txt"; then grep '^Error' "$work/dciodvfy.txt"; return 1; fi
}
# plastimatch's masks of `rtstruct` on `ct_dir` against `labels` (NIfTI): each ROI voxel for voxel.
plastimatch_agrees() {
  local rtstruct=$1 ct_dir=$2 labels=$3 names=$4 out=$work/pm_$RANDOM
  plastimatch convert --input "$rtstruct" --referenced-ct "$ct_dir" --xor-contours \
    --output-prefix "$out" --prefix-format nii.gz >"$out.log" 2>&1 || { cat "$out.log"; return 1; }
  /usr/bin/python3 - "$out" "$labels" "$names" <<'PY'
import json, sys, nibabel as nib, numpy as np
out, labels, names = sys.argv[1], nib.load(sys.argv[2]), json.loads(sys.argv[3])
ours = np.asarray(labels.dataobj)
for value, name in names.items():
    mask = nib.load(f"{out}/{name}.nii.gz")
    assert np.allclose(mask.affine, labels.affine, atol=1e-3), (name, mask.affine, labels.affine)
    theirs = np.asarray(mask.dataobj) > 0
    expected = ours == int(value)
    assert expected.any(), name
    diff = int((theirs != expected).sum())
    assert diff == 0, f"{name}: {diff} of {int(expected.sum())} voxels differ"
PY
}

"$bin" phantom --out "$work/ph" --spacing 4 --tumour idc,15,-25,10,8 >"$work/phantom.txt" 2>&1 \
  || { cat "$work/phantom.txt"; fail "phantom"; finish; exit; }
names='{"1": "skin", "2": "adipose", "3": "fibroglandular", "4": "muscle", "5": "bone", "6": "tumour"}'

if dicom_valid "$work/ph/rtstruct.dcm"; then pass "phantom rtstruct.dcm: dciodvfy finds no error"; else fail "phantom dciodvfy"; fi
if /usr/bin/python3 - "$work/ph" <<'PY'
import glob, sys, pydicom
d = sys.argv[1]
rs = pydicom.dcmread(f"{d}/rtstruct.dcm")
ct = [pydicom.dcmread(f) for f in sorted(glob.glob(f"{d}/dicom/*.dcm"))]
assert rs.Modality == "RTSTRUCT" and rs.SOPClassUID == "1.2.840.10008.5.1.4.1.1.481.3"
assert rs.StudyInstanceUID == ct[0].StudyInstanceUID and rs.PatientID == ct[0].PatientID
frame = rs.ReferencedFrameOfReferenceSequence[0]
assert frame.FrameOfReferenceUID == ct[0].FrameOfReferenceUID
series = frame.RTReferencedStudySequence[0].RTReferencedSeriesSequence[0]
assert series.SeriesInstanceUID == ct[0].SeriesInstanceUID
assert {i.ReferencedSOPInstanceUID for i in series.ContourImageSequence} == {c.SOPInstanceUID for c in ct}
names = [r.ROIName for r in rs.StructureSetROISequence]
assert names == ["skin", "adipose", "fibroglandular", "muscle", "bone", "tumour"], names
for roi in rs.ROIContourSequence:
    for c in roi.ContourSequence:
        assert c.ContourGeometricType == "CLOSED_PLANAR" and len(c.ContourData) == 3 * c.NumberOfContourPoints
PY
then pass "pydicom reads the phantom's structures and their references"; else fail "pydicom phantom"; fi
if plastimatch_agrees "$work/ph/rtstruct.dcm" "$work/ph/dicom" "$work/ph/labels.nii.gz" "$names"; then
  pass "plastimatch convert rasterises the phantom's contours to its label map"; else fail "plastimatch phantom"; fi
# Deterministic like the series: the same phantom gives the same bytes, UIDs included.
if "$bin" phantom --out "$work/ph_again" --spacing 4 --tumour idc,15,-25,10,8 >/dev/null 2>&1 \
   && cmp -s "$work/ph/rtstruct.dcm" "$work/ph_again/rtstruct.dcm"; then
  pass "the phantom's rtstruct.dcm is byte-identical on a rerun"; else fail "phantom rtstruct determinism"; fi

# The structures instead of the label map: the same model; the outputs carry them. The CT is the
# DICOM series, so the structures' frame of reference is checked against the CT's.
sed -e 's|^image = "ct.nii.gz"|image = "dicom"|' -e 's|^labels = "labels.nii.gz"|structures = "rtstruct.dcm"|' -e 's|^\[model.label_table\]|[model.structure_table]|' \
    -e 's|^[0-9] = \("[a-z]*"\)|\1 = \1|' -e 's|^max_steps = .*|max_steps = 300|' -e 's|^equilibrium = .*|equilibrium = 0.0|' \
    "$work/ph/scene.toml" >"$work/ph/structures.toml"
sed -e 's|^max_steps = .*|max_steps = 300|' -e 's|^equilibrium = .*|equilibrium = 0.0|' "$work/ph/scene.toml" >"$work/ph/labels.toml"
"$bin" simulate "$work/ph/labels.toml" --out "$work/by_labels" --quiet >"$work/labels.txt" 2>&1
if "$bin" simulate "$work/ph/structures.toml" --out "$work/by_structures" --quiet >"$work/structures.txt" 2>&1 \
   && cmp -s <(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["elements"])' "$work/by_labels/summary.json") \
             <(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["elements"])' "$work/by_structures/summary.json"); then
  pass "model.structures builds the model the label map builds"
else fail "model.structures"; cat "$work/structures.txt"; fi
out=$work/by_structures
if dicom_valid "$out/warped_structures.dcm"; then pass "warped_structures.dcm: dciodvfy finds no error"; else fail "warped dciodvfy"; fi
if /usr/bin/python3 - "$out" <<'PY'
import glob, sys, pydicom
d = sys.argv[1]
rs = pydicom.dcmread(f"{d}/warped_structures.dcm")
ct = [pydicom.dcmread(f) for f in sorted(glob.glob(f"{d}/warped_ct_dicom/*.dcm"))]
series = rs.ReferencedFrameOfReferenceSequence[0].RTReferencedStudySequence[0].RTReferencedSeriesSequence[0]
assert series.SeriesInstanceUID == ct[0].SeriesInstanceUID
assert rs.ReferencedFrameOfReferenceSequence[0].FrameOfReferenceUID == ct[0].FrameOfReferenceUID
PY
then pass "warped_structures.dcm references the warped CT series"; else fail "warped references"; fi
if plastimatch_agrees "$out/warped_structures.dcm" "$out/warped_ct_dicom" "$out/warped_labels.nii.gz" "$names"; then
  pass "plastimatch convert rasterises the warped contours to warped_labels.nii.gz"; else fail "plastimatch warped"; fi

# Bad structures: one line naming the ROI, non-zero exit, no result. Each case is the phantom's
# rtstruct.dcm changed by pydicom (python below) and/or the scene changed by sed.
edit_rtstruct() {  # name, python statements on `rs` (the dataset) and `roi(name)` (its contour item)
  /usr/bin/python3 - "$work/ph/rtstruct.dcm" "$work/ph/$1.dcm" "$2" <<'PY'
import sys, copy, pydicom
rs = pydicom.dcmread(sys.argv[1])
number = {r.ROIName: r.ROINumber for r in rs.StructureSetROISequence}
def roi(name):
    return next(c for c in rs.ROIContourSequence if c.ReferencedROINumber == number[name])
def info(name):
    return next(r for r in rs.StructureSetROISequence if r.ROIName == name)
exec(sys.argv[3])
rs.save_as(sys.argv[2])
PY
}
bad() {  # name, sed expression on structures.toml, expected text
  sed -e "$2" "$work/ph/structures.toml" >"$work/ph/bad.toml"
  if "$bin" simulate "$work/ph/bad.toml" --out "$work/bad_$1" --quiet >"$work/bad.txt" 2>&1; then fail "$1: exit 0"; return; fi
  if [[ $(grep -c . "$work/bad.txt") -eq 1 ]] && grep -q "$3" "$work/bad.txt" && [[ ! -e $work/bad_$1/result.h5 ]] \
     && [[ ! -e $work/bad_$1/summary.json ]]; then
    pass "$1: $(cat "$work/bad.txt")"; else fail "$1"; cat "$work/bad.txt"; fi
}
use() { echo "s|^structures = \"rtstruct.dcm\"|structures = \"$1.dcm\"|"; }
bad unmapped '/^"tumour" = /d' "ROI 'tumour'.*maps to no tissue"
bad missing_roi 's|^"skin" = "skin"|"skin" = "skin"\n"nipple" = "skin"|' "ROI 'nipple'"
edit_rtstruct frame 'info("tumour").ReferencedFrameOfReferenceUID = "1.2.826.0.1.3680043.2.1125.1"'
bad frame "$(use frame)" "ROI 'tumour'.*frame of reference.*not the CT's"
edit_rtstruct outside 'c = roi("tumour").ContourSequence[0]; d = [float(v) for v in c.ContourData]; d[0] += 1000; c.ContourData = d'
bad outside "$(use outside)" "ROI 'tumour'.*outside the image"
edit_rtstruct malformed 'c = roi("tumour").ContourSequence[0]; c.NumberOfContourPoints = int(c.NumberOfContourPoints) + 1'
bad malformed "$(use malformed)" "ROI 'tumour'.*malformed"
edit_rtstruct open_contour 'roi("tumour").ContourSequence[0].ContourGeometricType = "OPEN_PLANAR"'
bad open_contour "$(use open_contour)" "ROI 'tumour'.*OPEN_PLANAR"
# A boost volume drawn over the tumour: an overlap that needs a priority rule.
edit_rtstruct overlap '
new = copy.deepcopy(info("tumour")); new.ROINumber = 99; new.ROIName = "boost"; rs.StructureSetROISequence.append(new)
c = copy.deepcopy(roi("tumour")); c.ReferencedROINumber = 99; rs.ROIContourSequence.append(c)
o = copy.deepcopy(rs.RTROIObservationsSequence[0]); o.ObservationNumber = 99; o.ReferencedROINumber = 99
rs.RTROIObservationsSequence.append(o)'
bad overlap "$(use overlap)"'
s|^"tumour" = "tumour"|"tumour" = "tumour"\n"boost" = "tumour"|' "ROI 'boost'.*overlaps ROI 'tumour'.*no priority rule"
sed -e "$(use overlap)" -e 's|^"tumour" = "tumour"|"tumour" = "tumour"\n"boost" = "tumour"|' \
    -e 's|^\[model.structure_table\]|structure_priority = ["boost", "tumour"]\n\n[model.structure_table]|' \
    "$work/ph/structures.toml" >"$work/ph/priority.toml"
if "$bin" simulate "$work/ph/priority.toml" --out "$work/priority" --quiet >"$work/priority.txt" 2>&1 \
   && [[ -e $work/priority/summary.json ]]; then
  pass "model.structure_priority settles the overlap"; else fail "structure_priority"; cat "$work/priority.txt"; fi

finish
