#!/usr/bin/python3
"""Mid-slices of the input CT, the warped CT, their difference and the DVF magnitude.

    /usr/bin/python3 scripts/plot_warp.py data-samples/phantom/ct.nii.gz out/phantom docs/img/phantom_prone.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import nibabel as nib
import numpy as np


def main(ct_path, out_dir, png_path):
    ct = nib.load(ct_path).get_fdata()
    warped = nib.load(f"{out_dir}/warped_ct.nii.gz").get_fdata()
    dvf = np.asarray(nib.load(f"{out_dir}/dvf.nii.gz").dataobj)[:, :, :, 0, :]
    magnitude = np.linalg.norm(dvf, axis=-1)
    k = int(np.argmax(magnitude.max(axis=(0, 1))))  # the axial slice that moves most
    panels = [(ct, "input CT (supine phantom)", "gray", (-200, 200)),
              (warped, "warped CT (prone)", "gray", (-200, 200)),
              (warped - ct, "warped − input (HU)", "RdBu", (-300, 300)),
              (magnitude, "DVF magnitude (mm)", "viridis", (0, magnitude.max()))]
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.6))
    for ax, (img, title, cmap, (lo, hi)) in zip(axes, panels):
        im = ax.imshow(img[:, :, k].T, cmap=cmap, vmin=lo, vmax=hi, origin="upper")
        ax.set_title(title)
        ax.set_xlabel("voxel i (patient left →)")
        fig.colorbar(im, ax=ax, shrink=0.7)
    axes[0].set_ylabel("voxel j (posterior ↓)")
    fig.suptitle(f"axial slice k = {k}", y=0.98)
    fig.tight_layout()
    fig.savefig(png_path, dpi=90)


if __name__ == "__main__":
    main(*sys.argv[1:4])
