#!/usr/bin/python3
"""Checks that the RT tools Debian 12 ships read VoxBreast's outputs as VoxBreast means them.

Usage: check_rt_tools.py VOXBREAST_BINARY SOURCE_DIR
Runs the bundled phantom's main job (data-samples/phantom/scene_dicom.toml: the DICOM CT settling
prone; relaxation, 8 mm lattice, for speed) with the legacy NIfTI DVF layout, then:
- plastimatch warp and transformix resample the input CT with dvf_inverse.mha and with the
  legacy dvf_inverse.nii.gz, linear interpolation as VoxBreast's own warp: at most 0 voxels may
  differ from warped_ct.nii.gz by more than 1 HU, vacated voxels excepted (summary.json
  warp_vacated_voxels: tissue left them, so no resampling of the input CT gives their air);
- the same field in the standard layout (intent 1006, RAS) is not read as a displacement by
  either tool (docs/FORMATS.md's table says so: checked here, not assumed);
- plastimatch stats on dvf.mha and dvf_inverse.mha equal summary.json's dvf_stats_mm;
- dciodvfy finds 0 errors in every warped CT slice, in dvf_inverse.dcm, in warped_structures.dcm,
  in the bundled phantom series and in a fresh `voxbreast phantom`'s series and rtstruct.dcm;
  pydicom reads dvf_inverse.dcm's grid back equal to dvf_inverse.mha and the warped CT's
  SourceImageSequence names slices of the input series;
- RTSTRUCT: pydicom finds that warped_structures.dcm (and the phantom's rtstruct.dcm) references
  its CT series, every slice of it, and its frame of reference; `plastimatch convert` rasterises
  each ROI of both onto the referenced series, and its mask equals ours (warped_labels.nii.gz,
  labels.nii.gz) voxel for voxel: the measure is the count of voxels where the two masks differ,
  with the Dice coefficient printed, and the bound is 0 (our contours run along voxel edges, so
  no voxel centre lies on a contour and every rasteriser that tests voxel centres agrees).
Exit 0 when all checks pass, 1 on a failure, 77 (ctest SKIP_RETURN_CODE) when a tool is missing.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zlib

try:
    import nibabel as nib
    import numpy as np
    import pydicom
except ImportError as error:
    print(f"SKIP: {error}; install python3-nibabel and python3-pydicom (scripts/setup.sh)")
    sys.exit(77)

TOOLS = ("plastimatch", "transformix", "dciodvfy")
LABEL_NAMES = {1: "skin", 2: "adipose", 3: "fibroglandular", 4: "muscle", 5: "bone", 6: "tumour"}
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run(args, **kwargs):
    result = subprocess.run(args, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        print(" ".join(args), "\n", result.stdout[-3000:], result.stderr[-3000:])
    return result


def read_mha(path):
    """A 3-channel MetaImage as written by VoxBreast: (header dict, array (nz, ny, nx, 3))."""
    raw = open(path, "rb").read()
    end = raw.index(b"ElementDataFile = LOCAL\n") + len(b"ElementDataFile = LOCAL\n")
    header = dict(line.split(" = ", 1) for line in raw[:end].decode().splitlines())
    data = raw[end:]
    if header.get("CompressedData") == "True":
        data = zlib.decompress(data)
    nx, ny, nz = (int(v) for v in header["DimSize"].split())
    return header, np.frombuffer(data, "<f4").reshape(nz, ny, nx, 3)


def hu_of(path):
    return np.asarray(nib.load(path).dataobj, dtype=np.float64)


def compare_warp(name, produced, expected, vacated):
    image = hu_of(produced)
    off = np.abs(image - expected) > 1.0
    check(image.shape == expected.shape and int((off & ~vacated).sum()) == 0,
          f"{name}: {int((off & ~vacated).sum())} voxels off by more than 1 HU outside the "
          f"{int(vacated.sum())} vacated (max {np.abs(image - expected)[~vacated].max():.2f} HU)")
    return int(off.sum())


def plastimatch_warp(out, ct, xf, name):
    result = run(["plastimatch", "warp", "--input", ct, "--xf", xf, "--output-img", f"{out}/{name}.nii.gz",
                  "--interpolation", "linear", "--default-value", "-1000"])
    check(result.returncode == 0, f"plastimatch warp --xf {os.path.basename(xf)} exits 0")
    return f"{out}/{name}.nii.gz"


def transformix_warp(out, ct, xf, name):
    header, _ = read_mha(f"{out}/run/dvf_inverse.mha")
    folder = f"{out}/{name}"
    os.makedirs(folder)
    # ITK's frame: the grid as in the .mha header (LPS mm), which equals the CT's. Linear
    # interpolation is a B-spline of order 1: Debian's elastix 5.0.1 has no FinalLinearInterpolator.
    with open(f"{folder}/TransformParameters.txt", "w") as f:
        f.write(f"""(Transform "DeformationFieldTransform")
(DeformationFieldFileName "{xf}")
(DeformationFieldInterpolationOrder 1)
(NumberOfParameters 0)
(InitialTransformParametersFileName "NoInitialTransform")
(HowToCombineTransforms "Compose")
(FixedImageDimension 3)
(MovingImageDimension 3)
(FixedInternalImagePixelType "float")
(MovingInternalImagePixelType "float")
(Size {header["DimSize"]})
(Index 0 0 0)
(Spacing {header["ElementSpacing"]})
(Origin {header["Offset"]})
(Direction {" ".join(header["TransformMatrix"].split())})
(UseDirectionCosines "true")
(ResampleInterpolator "FinalBSplineInterpolator")
(FinalBSplineInterpolationOrder 1)
(Resampler "DefaultResampler")
(DefaultPixelValue -1000)
(ResultImageFormat "nii.gz")
(ResultImagePixelType "float")
(CompressResultImage "false")
""")
    result = run(["transformix", "-in", ct, "-out", folder, "-tp", f"{folder}/TransformParameters.txt"])
    check(result.returncode == 0, f"transformix with {os.path.basename(xf)} exits 0")
    return f"{folder}/result.nii.gz"


def plastimatch_stats(path):
    text = run(["plastimatch", "stats", path]).stdout
    rows = {}
    for key in ("Min", "Mean", "Max", "Mean abs"):
        match = re.search(rf"^{key}:\s+(\S+)\s+(\S+)\s+(\S+)", text, re.M)
        rows[key] = [float(v) for v in match.groups()] if match else None
    match = re.search(r"^Ave len:\s+(\S+)", text, re.M)
    rows["Ave len"] = [float(match.group(1))] if match else None
    return rows


def check_stats(name, path, ours):
    theirs = plastimatch_stats(path)
    pairs = {"Min": ours["min"], "Mean": ours["mean"], "Max": ours["max"], "Mean abs": ours["mean_abs"],
             "Ave len": [ours["mean_length"]]}
    for key, values in pairs.items():
        # plastimatch prints 3 decimals: equal within half a unit of the last digit
        same = theirs[key] is not None and all(abs(a - b) <= 0.0005 + 1e-6 for a, b in zip(theirs[key], values))
        check(same, f"plastimatch stats {name} {key}: {theirs[key]} vs summary.json {[round(v, 4) for v in values]}")


def dciodvfy_errors(path):
    result = subprocess.run(["dciodvfy", path], capture_output=True, text=True)
    return [line for line in (result.stdout + result.stderr).splitlines() if line.startswith("Error")]


def check_rtstruct(out, name, rtstruct, ct_dir, labels_path):
    """pydicom's view of `rtstruct`'s references; plastimatch's masks of it against our label map."""
    errors = dciodvfy_errors(rtstruct)
    check(not errors, f"dciodvfy: {len(errors)} errors in {name}" + (f" (first: {errors[0]})" if errors else ""))
    rs = pydicom.dcmread(rtstruct)
    ct = [pydicom.dcmread(f, stop_before_pixels=True) for f in sorted(glob.glob(f"{ct_dir}/*.dcm"))]
    frame = rs.ReferencedFrameOfReferenceSequence[0]
    series = frame.RTReferencedStudySequence[0].RTReferencedSeriesSequence[0]
    check(rs.Modality == "RTSTRUCT" and rs.StudyInstanceUID == ct[0].StudyInstanceUID
          and frame.FrameOfReferenceUID == ct[0].FrameOfReferenceUID
          and series.SeriesInstanceUID == ct[0].SeriesInstanceUID
          and {i.ReferencedSOPInstanceUID for i in series.ContourImageSequence} == {c.SOPInstanceUID for c in ct},
          f"pydicom: {name} references its CT series ({len(ct)} slices), study and frame of reference")
    masks = f"{out}/masks_{name.replace('.', '_')}"
    result = run(["plastimatch", "convert", "--input", rtstruct, "--referenced-ct", ct_dir, "--xor-contours",
                  "--output-prefix", masks, "--prefix-format", "nii.gz"])
    check(result.returncode == 0, f"plastimatch convert --input {name} exits 0")
    if result.returncode != 0:
        return
    labels = nib.load(labels_path)
    ours = np.asarray(labels.dataobj)
    names = {r.ROINumber: r.ROIName for r in rs.StructureSetROISequence}
    for number, roi in names.items():
        expected = ours == int(number)
        path = f"{masks}/{roi}.nii.gz"
        if not os.path.exists(path):
            check(False, f"plastimatch wrote no mask for {name} ROI '{roi}'")
            continue
        mask = nib.load(path)
        theirs = np.asarray(mask.dataobj) > 0
        same_grid = theirs.shape == expected.shape and np.allclose(mask.affine, labels.affine, atol=1e-3)
        differ = int((theirs != expected).sum()) if same_grid else -1
        dice = 2 * int((theirs & expected).sum()) / max(1, int(theirs.sum() + expected.sum())) if same_grid else 0
        check(same_grid and differ == 0 and expected.any(),
              f"plastimatch's mask of {name} ROI '{roi}': {differ} of {int(expected.sum())} voxels differ "
              f"from ours (Dice {dice:.4f})")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    missing = [tool for tool in TOOLS if shutil.which(tool) is None]
    if missing:
        print(f"SKIP: {', '.join(missing)} missing; install plastimatch, elastix and dicom3tools (scripts/setup.sh)")
        return 77
    binary, source = sys.argv[1], sys.argv[2]
    phantom = f"{source}/data-samples/phantom"
    with tempfile.TemporaryDirectory(prefix="vb_rt_tools_") as out:
        started = time.time()
        sim = run([binary, "simulate", f"{phantom}/scene_dicom.toml", "--out", f"{out}/run", "--quiet",
                   "--set", "+solver.integrator=relaxation", "--set", "model.spacing=0.008",
                   "--set", "+output.dvf_nifti=legacy"])
        check(sim.returncode == 0, f"voxbreast simulate ({time.time() - started:.1f} s)")
        if sim.returncode != 0:
            return 1
        summary = json.load(open(f"{out}/run/summary.json"))["image_outputs"]
        ct = f"{phantom}/ct.nii.gz"
        expected = hu_of(f"{out}/run/warped_ct.nii.gz")
        _, inverse = read_mha(f"{out}/run/dvf_inverse.mha")
        moved = np.abs(inverse).max(axis=3).transpose(2, 1, 0) > 0  # (nx, ny, nz), as nibabel
        # Vacated voxels: tissue at rest, none arrived; the warp fills them with the CT's lowest value.
        vacated = (expected == hu_of(ct).min()) & ~moved & (hu_of(ct) != expected)
        check(int(vacated.sum()) == summary["warp_vacated_voxels"],
              f"{int(vacated.sum())} vacated voxels found, summary.json says {summary['warp_vacated_voxels']}")
        check(int(moved.sum()) > 1000, f"the warp moves {int(moved.sum())} voxels")
        legacy = nib.load(f"{out}/run/dvf_inverse.nii.gz")
        check(int(legacy.header["intent_code"]) == 1007, "output.dvf_nifti = legacy writes intent 1007")
        check(np.allclose(np.asarray(legacy.dataobj)[:, :, :, 0, :], inverse.transpose(2, 1, 0, 3), atol=1e-5),
              "the legacy NIfTI holds the .mha's LPS vectors")

        started = time.time()
        for xf in ("dvf_inverse.mha", "dvf_inverse.nii.gz"):
            produced = plastimatch_warp(out, ct, f"{out}/run/{xf}", "plastimatch_" + xf.replace(".", "_"))
            compare_warp(f"plastimatch warp with {xf}", produced, expected, vacated)
            produced = transformix_warp(out, ct, f"{out}/run/{xf}", "transformix_" + xf.replace(".", "_"))
            compare_warp(f"transformix with {xf}", produced, expected, vacated)
        # The standard layout (intent 1006, RAS components) of the same field, as dvf_nifti =
        # "standard" writes it (docs/FORMATS.md): ITK 5.2 does not take it as a displacement.
        standard = nib.Nifti1Image(np.asarray(legacy.dataobj) * np.array([-1, -1, 1], np.float32), legacy.affine,
                                   legacy.header)
        standard.header.set_intent(1006, name="displacement")
        nib.save(standard, f"{out}/dvf_inverse_standard.nii.gz")
        produced = plastimatch_warp(out, ct, f"{out}/dvf_inverse_standard.nii.gz", "plastimatch_standard")
        off = int((np.abs(hu_of(produced) - expected) > 1).sum())
        check(off > 1000, f"plastimatch warp misreads the standard layout: {off} voxels off by more than 1 HU")
        produced = transformix_warp(out, ct, f"{out}/dvf_inverse_standard.nii.gz", "transformix_standard")
        off = int((np.abs(hu_of(produced) - expected) > 1).sum()) if os.path.exists(produced) else -1
        check(off != 0, f"transformix does not reproduce the warp from the standard layout ({off} voxels off)")
        print(f"      (the warps took {time.time() - started:.1f} s)")

        check_stats("dvf.mha", f"{out}/run/dvf.mha", summary["dvf_stats_mm"])
        check_stats("dvf_inverse.mha", f"{out}/run/dvf_inverse.mha", summary["dvf_inverse_stats_mm"])

        written = sorted(glob.glob(f"{out}/run/warped_ct_dicom/*.dcm"))
        bundled = sorted(glob.glob(f"{phantom}/dicom/*.dcm"))
        for name, files in (("warped CT slices", written), ("bundled phantom slices", bundled),
                            ("dvf_inverse.dcm", [f"{out}/run/dvf_inverse.dcm"])):
            errors = [e for f in files for e in dciodvfy_errors(f)]
            check(files and not errors, f"dciodvfy: {len(errors)} errors in {len(files)} {name}" +
                  (f" (first: {errors[0]})" if errors else ""))

        check_rtstruct(out, "warped_structures.dcm", f"{out}/run/warped_structures.dcm", f"{out}/run/warped_ct_dicom",
                       f"{out}/run/warped_labels.nii.gz")
        fresh = run([binary, "phantom", "--out", f"{out}/phantom", "--spacing", "4", "--tumour", "idc,15,-20,10,8"])
        check(fresh.returncode == 0, "voxbreast phantom")
        if fresh.returncode == 0:
            slices = sorted(glob.glob(f"{out}/phantom/dicom/*.dcm"))
            errors = [e for f in slices for e in dciodvfy_errors(f)]
            check(slices and not errors, f"dciodvfy: {len(errors)} errors in {len(slices)} fresh phantom slices")
            check_rtstruct(out, "rtstruct.dcm", f"{out}/phantom/rtstruct.dcm", f"{out}/phantom/dicom",
                           f"{out}/phantom/labels.nii.gz")

        source_uids = {pydicom.dcmread(f, stop_before_pixels=True).SOPInstanceUID for f in bundled}
        first = pydicom.dcmread(written[0], stop_before_pixels=True)
        referenced = {item.ReferencedSOPInstanceUID for item in first.SourceImageSequence}
        check(referenced and referenced <= source_uids, f"warped slice 1 derives from {len(referenced)} input slices")
        check(first.PatientPosition == "HFP", f"the warped CT lies prone: PatientPosition {first.PatientPosition}")
        check(pydicom.dcmread(bundled[0]).PatientPosition == "HFS", "the bundled phantom lies supine: HFS")
        reg = pydicom.dcmread(f"{out}/run/dvf_inverse.dcm")
        grid = reg.DeformableRegistrationSequence[0].DeformableRegistrationGridSequence[0]
        vectors = np.frombuffer(grid.VectorGridData, "<f4").reshape(inverse.shape)
        check([int(v) for v in grid.GridDimensions] == list(inverse.shape[2::-1]) and np.array_equal(vectors, inverse),
              "dvf_inverse.dcm's vector grid equals dvf_inverse.mha")
        check(reg.FrameOfReferenceUID == first.FrameOfReferenceUID and reg.StudyInstanceUID == first.StudyInstanceUID,
              "dvf_inverse.dcm shares the warped CT's frame of reference and study")
        series = {item.SeriesInstanceUID for item in reg.ReferencedSeriesSequence}
        check(series == {first.SeriesInstanceUID, pydicom.dcmread(bundled[0]).SeriesInstanceUID},
              "dvf_inverse.dcm references the input and the warped CT series")
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
