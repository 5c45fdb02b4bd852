#!/usr/bin/python3
"""Renders a positioning run with its device (output.surfaces = true): the deformed breast surface
coloured by displacement with the device's tori (device_*.vtp), and a section through the breast
axis comparing the rest and final outlines with the tori's cross-sections. For docs/.

    /usr/bin/python3 scripts/plot_device.py OUT_DIR docs/img/device_phantom.png [SECTION_AXIS]

SECTION_AXIS (x, y or z, default z) is the world axis normal to the section plane through 0.
"""
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader


def read(path, with_displacement=True):
    r = vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    poly = r.GetOutput()
    points = vtk_to_numpy(poly.GetPoints().GetData())
    cells = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    disp = vtk_to_numpy(poly.GetPointData().GetArray("displacement_mm")) if with_displacement else None
    return points, cells, disp


def shade(points, cells, rgba):
    faces = points[cells]
    normal = np.cross(faces[:, 1] - faces[:, 0], faces[:, 2] - faces[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    light = np.array([-0.4, -0.8, 0.45])  # from the front (anterior, −y), left and above
    lit = 0.35 + 0.65 * np.clip(normal @ (light / np.linalg.norm(light)), 0, 1)
    rgba = rgba.copy()
    rgba[:, :3] *= lit[:, None]
    return faces, rgba


def section(points, cells, axis, value=0.0):
    """Segments where the triangle mesh crosses the plane points[:, axis] = value."""
    segments = []
    for tri in points[cells]:
        s = tri[:, axis] - value
        crossing = []
        for a, b in ((0, 1), (1, 2), (2, 0)):
            if (s[a] < 0) != (s[b] < 0):
                t = s[a] / (s[a] - s[b])
                crossing.append(tri[a] + t * (tri[b] - tri[a]))
        if len(crossing) == 2:
            segments.append(crossing)
    return np.array(segments)


def main(run_dir, png, axis_name="z"):
    axis = "xyz".index(axis_name)
    rest, cells, _ = read(f"{run_dir}/surface_rest.vtp")
    moved, _, disp = read(f"{run_dir}/surface.vtp")
    tori = {os.path.basename(p)[len("device_"):-4]: read(p, False) for p in sorted(glob.glob(f"{run_dir}/device_*.vtp"))}
    magnitude = np.linalg.norm(disp, axis=1)
    cmap = plt.get_cmap("viridis")
    norm = matplotlib.colors.Normalize(0, magnitude.max())

    fig = plt.figure(figsize=(13, 5.8))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    # Breast faces in front of the chest wall (y < 2 mm) and the tori in one collection, so
    # matplotlib sorts them together by depth.
    front = moved[cells][:, :, 1].max(axis=1) < 2.0
    faces, rgba = shade(moved, cells[front], cmap(norm(magnitude[cells[front]].mean(axis=1))))
    colours = plt.get_cmap("Set1")
    all_faces, all_rgba = [faces], [rgba]
    for i, (name, (points, tcells, _)) in enumerate(tori.items()):
        base = np.tile(np.array(colours(i)), (len(tcells), 1))
        base[:, 3] = 0.45
        tfaces, trgba = shade(points, tcells, base)
        all_faces.append(tfaces)
        all_rgba.append(trgba)
    ax.add_collection3d(Poly3DCollection(np.concatenate(all_faces), facecolors=np.concatenate(all_rgba),
                                         edgecolors="none", linewidths=0))
    everything = np.vstack([moved[cells[front]].reshape(-1, 3)] + [p for p, _, _ in tori.values()])
    centre, half = everything.mean(axis=0), (everything.max(axis=0) - everything.min(axis=0)).max() / 2
    for k, name in enumerate("xyz"):
        getattr(ax, f"set_{name}lim")(centre[k] - half, centre[k] + half)
    ax.set_xlabel("x (L, mm)")
    ax.set_ylabel("y (P, mm)")
    ax.set_zlabel("z (S, mm)")
    ax.view_init(elev=20, azim=-60)
    ax.set_title("final state: breast (by displacement) and device")
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6, pad=0.1)
    bar.set_label("displacement (mm)")

    ax2 = fig.add_subplot(1, 2, 2)
    u, v = [k for k in range(3) if k != axis]
    for pts, colour, label in ((rest, "0.6", "breast at rest (CT)"), (moved, "k", "breast, final")):
        segs = section(pts, cells, axis)
        for j, s in enumerate(segs):
            ax2.plot(s[:, u], s[:, v], color=colour, lw=1.2, label=label if j == 0 else None)
    for i, (name, (points, tcells, _)) in enumerate(tori.items()):
        for j, s in enumerate(section(points, tcells, axis)):
            ax2.plot(s[:, u], s[:, v], color=colours(i), lw=1.5, label=name if j == 0 else None)
    ax2.set_aspect("equal")
    ax2.set_xlabel(f"{'xyz'[u]} (mm)")
    ax2.set_ylabel(f"{'xyz'[v]} (mm)")
    ax2.set_title(f"section {axis_name} = 0 (prone: anterior, −y, is down)" if axis_name == "z" else f"section {axis_name} = 0")
    ax2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.3), ncol=4, fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=100)


if __name__ == "__main__":
    main(*sys.argv[1:4])
