#!/usr/bin/python3
"""Checks VoxBreast's mesh files with VTK's own readers (Debian python3-vtk9) and the lattice
.vtu also with meshio (Debian python3-meshio), the Python mesh stack's reader.

Usage: check_meshes_vtk.py TEST_SURFACE_BINARY
Runs the binary's MeshFilesForVtk test, which writes .vtp/.vtu/.ply/.stl files and expected.json
into a temporary folder, then reads each file with vtkXMLPolyDataReader,
vtkXMLUnstructuredGridReader, vtkPLYReader and vtkSTLReader and checks point and cell counts,
arrays, the SPACE=LPS field of the .vtp files, the tissue ids of the .vtu, closedness, and volumes
(mesh volume by vtkMassProperties, hexahedron volumes by vtkCellSizeFilter, which also checks
VTK's corner order); then reads each .vtu with meshio.read and checks points, hexahedra, point data
and the tissue ids in its field data.
Exit 0 when all checks pass, 1 on a failure, 77 (ctest SKIP_RETURN_CODE) without VTK or meshio.
"""
import json
import os
import subprocess
import sys
import tempfile

try:
    from vtkmodules.vtkCommonCore import vtkIdList
    from vtkmodules.vtkCommonDataModel import VTK_HEXAHEDRON
    from vtkmodules.vtkFiltersCore import vtkFeatureEdges, vtkMassProperties
    from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
    from vtkmodules.vtkIOGeometry import vtkSTLReader
    from vtkmodules.vtkIOPLY import vtkPLYReader
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
    import meshio
    import numpy as np
except ImportError as error:
    print(f"SKIP: {error}; install python3-vtk9 and python3-meshio (scripts/setup.sh)")
    sys.exit(77)

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def close(a, b, rel=1e-6):
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))


def read(reader_class, path):
    reader = reader_class()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def field_string(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    return array.GetValue(0) if array is not None and array.GetNumberOfValues() > 0 else None


def check_polydata(name, path, exp, deformed):
    poly = read(vtkXMLPolyDataReader, path)
    check(poly.GetNumberOfPoints() == exp["points"], f"{name}: {poly.GetNumberOfPoints()} points, expected {exp['points']}")
    check(poly.GetNumberOfPolys() == exp["triangles"] and poly.GetNumberOfCells() == exp["triangles"],
          f"{name}: {poly.GetNumberOfPolys()} triangles, expected {exp['triangles']}")
    check(field_string(poly, "SPACE") == "LPS", f"{name}: field SPACE = {field_string(poly, 'SPACE')!r}")
    for array in exp["point_arrays"]:
        a = poly.GetPointData().GetArray(array)
        check(a is not None and a.GetNumberOfTuples() == exp["points"], f"{name}: point array {array}")
    disp = poly.GetPointData().GetArray("displacement_mm")
    if disp is not None:
        check(disp.GetNumberOfComponents() == 3, f"{name}: displacement_mm has 3 components")
        top = max(disp.GetRange(c)[1] for c in range(3))
        want = exp["max_displacement_mm"] if deformed else 0.0
        check(top <= want + 1e-9 and (not deformed or top > 0), f"{name}: largest displacement {top:.4g} mm ≤ {want:.4g}")
    edges = vtkFeatureEdges()
    edges.SetInputData(poly)
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOn()
    edges.FeatureEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    check(edges.GetOutput().GetNumberOfCells() == 0,
          f"{name}: {edges.GetOutput().GetNumberOfCells()} boundary or non-manifold edges (VTK)")
    mass = vtkMassProperties()
    mass.SetInputData(poly)
    mass.Update()
    # VTK's volume is unsigned; the signed check below uses the triangles directly.
    check(close(mass.GetVolume(), exp["volume_mm3"]), f"{name}: volume {mass.GetVolume():.6g} mm³, expected {exp['volume_mm3']:.6g}")
    points, polys = poly.GetPoints(), poly.GetPolys()
    polys.InitTraversal()
    ids, six_v = vtkIdList(), 0.0
    while polys.GetNextCell(ids):
        a, b, c = (points.GetPoint(ids.GetId(k)) for k in range(3))
        six_v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]))
    check(close(six_v / 6, exp["volume_mm3"]), f"{name}: signed volume {six_v / 6:.6g} mm³ (outward triangles)")


def check_grid(name, path, exp):
    grid = read(vtkXMLUnstructuredGridReader, path)
    check(grid.GetNumberOfPoints() == exp["elements"], f"{name}: {grid.GetNumberOfPoints()} points, expected {exp['elements']}")
    check(grid.GetNumberOfCells() == exp["hexahedra"], f"{name}: {grid.GetNumberOfCells()} cells, expected {exp['hexahedra']}")
    types = {grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}
    check(types == {VTK_HEXAHEDRON}, f"{name}: cell types {sorted(types)}")
    for tissue_id, tissue in enumerate(exp["tissues"]):
        a = grid.GetFieldData().GetArray(tissue)
        check(a is not None and a.GetNumberOfTuples() == 1 and a.GetValue(0) == tissue_id,
              f"{name}: field data {tissue!r} = tissue id {tissue_id}")
    for array in ("displacement_mm", "tissue", "equivalent_strain"):
        a = grid.GetPointData().GetArray(array)
        check(a is not None and a.GetNumberOfTuples() == exp["elements"], f"{name}: point array {array}")
    sizes = vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.ComputeVolumeOn()
    sizes.Update()
    volumes = sizes.GetOutput().GetCellData().GetArray("Volume")
    smallest = min(volumes.GetValue(i) for i in range(volumes.GetNumberOfTuples()))
    total = sum(volumes.GetValue(i) for i in range(volumes.GetNumberOfTuples()))
    check(smallest > 0, f"{name}: every hexahedron has positive volume (VTK corner order), smallest {smallest:.4g} mm³")
    check(close(total, exp["volume_mm3"]), f"{name}: hexahedra volume {total:.6g} mm³, expected {exp['volume_mm3']:.6g}")


def check_grid_meshio(name, path, exp):
    try:
        mesh = meshio.read(path)
    except Exception as error:  # meshio raises its own ReadError and others
        check(False, f"{name}: meshio.read fails: {error}")
        return
    check(len(mesh.points) == exp["elements"], f"{name} (meshio): {len(mesh.points)} points")
    hexahedra = sum(len(block.data) for block in mesh.cells if block.type == "hexahedron")
    check(hexahedra == exp["hexahedra"] and all(block.type == "hexahedron" for block in mesh.cells),
          f"{name} (meshio): {hexahedra} hexahedra, expected {exp['hexahedra']}")
    for array in ("displacement_mm", "tissue", "equivalent_strain"):
        check(array in mesh.point_data and len(mesh.point_data[array]) == exp["elements"],
              f"{name} (meshio): point array {array}")
    names = {tissue: int(np.asarray(ids).ravel()[0]) for tissue, ids in mesh.field_data.items()}
    check(names == {tissue: i for i, tissue in enumerate(exp["tissues"])}, f"{name} (meshio): tissue ids {names}")
    if "tissue" in mesh.point_data:
        used = set(np.unique(mesh.point_data["tissue"]).tolist())
        check(used <= set(names.values()), f"{name} (meshio): every point's tissue has a name")


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    with tempfile.TemporaryDirectory(prefix="vb_vtk_check_") as out:
        env = dict(os.environ, VOXBREAST_MESH_CHECK_DIR=out)
        run = subprocess.run([sys.argv[1], "--gtest_filter=MeshFilesForVtk.*"], env=env, capture_output=True, text=True)
        if run.returncode != 0 or not os.path.exists(os.path.join(out, "expected.json")):
            print(run.stdout, run.stderr)
            print("FAIL  the generator did not write the meshes")
            return 1
        with open(os.path.join(out, "expected.json")) as f:
            expected = json.load(f)
        for name, exp in expected.items():
            base = os.path.join(out, name)
            check_polydata(name + "_rest.vtp", base + "_rest.vtp", exp, deformed=False)
            check_polydata(name + "_deformed.vtp", base + "_deformed.vtp", exp, deformed=True)
            check_grid(name + ".vtu", base + ".vtu", exp)
            check_grid_meshio(name + ".vtu", base + ".vtu", exp)
            ply = read(vtkPLYReader, base + ".ply")
            check(ply.GetNumberOfPoints() == exp["points"] and ply.GetNumberOfCells() == exp["triangles"],
                  f"{name}.ply: {ply.GetNumberOfPoints()} points, {ply.GetNumberOfCells()} triangles")
            stl = read(vtkSTLReader, base + ".stl")  # merges coincident points
            check(stl.GetNumberOfCells() == exp["triangles"], f"{name}.stl: {stl.GetNumberOfCells()} triangles")
            mass = vtkMassProperties()
            mass.SetInputData(stl)
            mass.Update()
            check(close(mass.GetVolume(), exp["volume_mm3"], 1e-5), f"{name}.stl: volume {mass.GetVolume():.6g} mm³")
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
