"""The elastic body of hyperelastic tissue in VoxBreast: the union of the dual cells of the
element centres (PHYSICS.md, "Element volume"). numpy only, so the scenes need no FE package."""
import numpy as np


def complete_dual_cells(ijk):
    """Lower corners (integer element positions) of the dual cells whose 8 elements all exist."""
    ijk = np.asarray(ijk, dtype=np.int64)
    lo = ijk.min(axis=0)
    span = ijk.max(axis=0) - lo + 2
    occupied = np.zeros(span, dtype=bool)
    rel = ijk - lo
    occupied[rel[:, 0], rel[:, 1], rel[:, 2]] = True
    full = np.ones(span - 1, dtype=bool)
    for a in (0, 1):
        for b in (0, 1):
            for c in (0, 1):
                full &= occupied[a:span[0] - 1 + a, b:span[1] - 1 + b, c:span[2] - 1 + c]
    return np.argwhere(full) + lo


def hull_elements(ijk):
    """The elements that are a corner of some complete dual cell (the vertices of the body)."""
    corners = complete_dual_cells(ijk)
    local = np.array([(a, b, c) for c in (0, 1) for b in (0, 1) for a in (0, 1)])
    return np.unique((corners[:, None, :] + local[None, :, :]).reshape(-1, 3), axis=0)


def dual_cell_hexes(ijk, r):
    """Hexahedra of the union of dual cells of the elements at integer positions ijk (N x 3),
    each dual cell split into r^3. Returns (vertices in units of the element spacing, cells as
    vertex indices in dolfinx's tensor-product order, cell centres in the same units)."""
    corners = complete_dual_cells(ijk)  # dual cells' lower corners
    if len(corners) == 0:
        raise ValueError("the element set has no complete dual cell")
    sub = np.array([(a, b, c) for c in range(r) for b in range(r) for a in range(r)])
    lower = (corners[:, None, :] * r + sub[None, :, :]).reshape(-1, 3)  # sub-cell lower corners
    local = np.array([(a, b, c) for c in (0, 1) for b in (0, 1) for a in (0, 1)])  # x fastest
    verts = (lower[:, None, :] + local[None, :, :]).reshape(-1, 3)
    uniq, inverse = np.unique(verts, axis=0, return_inverse=True)
    cells = inverse.reshape(-1, 8).astype(np.int64)
    x = uniq.astype(float) / r
    centres = (lower.astype(float) + 0.5) / r
    return x, cells, centres


