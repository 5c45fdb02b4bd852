#!/usr/bin/python3
"""Renders a run's surface before and after the deformation (surface_rest.vtp and surface.vtp,
written with output.surfaces = true), coloured by displacement, for docs/.

    /usr/bin/python3 scripts/plot_surface.py OUT_DIR docs/img/phantom_surface.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader


def read(path):
    r = vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    poly = r.GetOutput()
    points = vtk_to_numpy(poly.GetPoints().GetData())
    cells = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    disp = vtk_to_numpy(poly.GetPointData().GetArray("displacement_mm"))
    return points, cells, disp


def draw(ax, points, cells, colour, title, limits, cmap, norm):
    faces = points[cells]
    rgba = cmap(norm(colour[cells].mean(axis=1))) if colour is not None else np.tile([0.85, 0.75, 0.7, 1], (len(cells), 1))
    normal = np.cross(faces[:, 1] - faces[:, 0], faces[:, 2] - faces[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    light = np.array([-0.4, -0.8, 0.45])  # from the front (anterior, −y), left and above
    lit = 0.35 + 0.65 * np.clip(normal @ (light / np.linalg.norm(light)), 0, 1)
    rgba[:, :3] *= lit[:, None]
    coll = Poly3DCollection(faces, facecolors=rgba, edgecolors="none", linewidths=0)
    ax.add_collection3d(coll)
    for axis, (lo, hi) in zip("xyz", limits):
        getattr(ax, f"set_{axis}lim")(lo, hi)
    ax.set_xlabel("x (L, mm)")
    ax.set_ylabel("y (P, mm)")
    ax.set_zlabel("z (S, mm)")
    ax.view_init(elev=20, azim=-115)
    ax.set_title(title)


def main(run_dir, png):
    rest, cells, _ = read(f"{run_dir}/surface_rest.vtp")
    moved, cells2, disp = read(f"{run_dir}/surface.vtp")
    assert (cells == cells2).all()
    magnitude = np.linalg.norm(disp, axis=1)
    both = np.vstack([rest, moved])
    limits = [(both[:, i].min(), both[:, i].max()) for i in range(3)]
    cmap = plt.get_cmap("viridis")
    norm = matplotlib.colors.Normalize(0, magnitude.max())
    fig = plt.figure(figsize=(12, 5.5))
    draw(fig.add_subplot(1, 2, 1, projection="3d"), rest, cells, None, "rest (as imaged)", limits, cmap, norm)
    draw(fig.add_subplot(1, 2, 2, projection="3d"), moved, cells, magnitude, "after the posture change", limits, cmap,
         norm)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=fig.axes, shrink=0.6)
    bar.set_label("displacement (mm)")
    fig.savefig(png, dpi=100)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
