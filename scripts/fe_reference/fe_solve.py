"""Finite-element reference solutions (FEniCSx / dolfinx 0.5) of VoxBreast's cross-check cases.

The body is the union of the dual cells of an element set (the cubes whose eight corners are
element centres): exactly the elastic body VoxBreast gives hyperelastic tissue. Each dual cell is
split into r^3 hexahedra; displacement is continuous Q2, pressure continuous Q1 (Taylor-Hood, a
stable mixed pair), so nearly incompressible tissue does not lock. The energy is VoxBreast's
decoupled compressible neo-Hookean form,

    W = mu/2 (J^(-2/3) I1 - 3) + kappa/2 (J - 1)^2,

written as the saddle point  W_dev + p (J - 1) - p^2 / (2 kappa), whose stationarity in p gives
p = kappa (J - 1) and so exactly W. Loads are the weight of the body (rho g over the hull), held
faces (u = 0) and prescribed normal displacements without friction (plates, a flat punch).

Newton's method runs in load increments; an increment that does not converge is halved (down to
1/64 of the load). A solve that still fails is reported with converged = false, and the
comparison driver refuses to use it.
"""
import logging
import time

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.fem.petsc import NonlinearProblem
from dolfinx.nls.petsc import NewtonSolver

from hull import dual_cell_hexes

logging.getLogger().setLevel(logging.WARNING)


class Body:
    """A dual-cell body: element positions ijk (units of h) with world position (ijk + 1/2) h."""

    def __init__(self, ijk, h, r):
        x_units, cells, centres_units = dual_cell_hexes(ijk, r)
        self.h = h
        x = (x_units + 0.5) * h
        domain = ufl.Mesh(ufl.VectorElement("Lagrange", "hexahedron", 1))
        self.mesh = dmesh.create_mesh(MPI.COMM_WORLD, cells, x, domain)
        self.n_cells = len(cells)
        self.volume = len(cells) * (h / r) ** 3


def _cell_midpoints(msh):
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local
    dofmap = msh.geometry.dofmap
    xg = msh.geometry.x
    return np.array([xg[dofmap.links(c)].mean(axis=0) for c in range(n)])


def solve(body, materials, material_of, gravity, rho_of, fixed, sliding, probes,
          reactions=(), degree=2, load_steps=1, rtol=1e-10):
    """Solves the static problem on body.

    materials: list of (mu, kappa); material_of(points (M x 3)) -> material index per point.
    rho_of(points) -> density per point (kg/m^3). gravity: vec3 (m/s^2).
    fixed: marker(x) -> bool for nodes held (u = 0).
    sliding: list of (marker, component, value): u[component] = value on the marked nodes
             (frictionless plates and punches; value in m, scaled with the load).
    probes: dict name -> (point, component): u[component] at point (m).
    reactions: dict name -> (marker, component): sum of the reaction on the marked nodes (N),
               the force the body exerts on what holds them (sign: along +component).
    Returns a dict with converged, newton iterations, the probes, reactions, dofs and time."""
    t0 = time.time()
    msh = body.mesh
    cell = msh.ufl_cell().cellname()
    Ve = ufl.VectorElement("Lagrange", cell, degree)
    Qe = ufl.FiniteElement("Lagrange", cell, degree - 1)
    W = fem.FunctionSpace(msh, ufl.MixedElement([Ve, Qe]))
    w = fem.Function(W)
    u, p = ufl.split(w)
    dw = ufl.TestFunction(W)

    mid = _cell_midpoints(msh)
    DG0 = fem.FunctionSpace(msh, ("DG", 0))
    mu_f, kappa_f, rho_f = fem.Function(DG0), fem.Function(DG0), fem.Function(DG0)
    idx = np.asarray(material_of(mid))
    mu_f.x.array[:] = np.array([materials[i][0] for i in idx])
    kappa_f.x.array[:] = np.array([materials[i][1] for i in idx])
    rho_f.x.array[:] = np.asarray(rho_of(mid), dtype=float)

    scale = fem.Constant(msh, PETSc.ScalarType(0.0))
    g = fem.Constant(msh, np.asarray(gravity, dtype=PETSc.ScalarType))
    d = len(u)
    I = ufl.Identity(d)
    F = I + ufl.grad(u)
    J = ufl.det(F)
    I1 = ufl.tr(F.T * F)
    psi = (mu_f / 2) * (J ** (-2.0 / 3.0) * I1 - 3) + p * (J - 1) - p ** 2 / (2 * kappa_f)
    dx = ufl.dx(metadata={"quadrature_degree": 2 * degree})
    Pi = psi * dx - scale * rho_f * ufl.dot(g, u) * dx
    R = ufl.derivative(Pi, w, dw)
    Jac = ufl.derivative(R, w, ufl.TrialFunction(W))

    V, _ = W.sub(0).collapse()
    bcs, moving = [], []
    if fixed is not None:
        zero = fem.Function(V)
        dofs = fem.locate_dofs_geometrical((W.sub(0), V), fixed)
        bcs.append(fem.dirichletbc(zero, dofs, W.sub(0)))
    for marker, comp, value in sliding:
        Vc, _ = W.sub(0).sub(comp).collapse()
        f = fem.Function(Vc)
        dofs = fem.locate_dofs_geometrical((W.sub(0).sub(comp), Vc), marker)
        bcs.append(fem.dirichletbc(f, dofs, W.sub(0).sub(comp)))
        moving.append((f, value))

    problem = NonlinearProblem(R, w, bcs=bcs, J=Jac)
    solver = NewtonSolver(MPI.COMM_WORLD, problem)
    # Absolute residual test against the body's force scale (dolfinx's relative residual is
    # measured from a reference that lets it stop an iteration early): the weight, or the
    # shear modulus over the body's cross-section for displacement-driven cases.
    volume = body.volume
    mu_max = max(m[0] for m in materials)
    rho_max = float(np.max(rho_f.x.array))
    force_scale = max(rho_max * float(np.linalg.norm(gravity)) * volume, mu_max * volume ** (2.0 / 3.0))
    solver.convergence_criterion = "residual"
    solver.rtol = 1e-14
    solver.atol = rtol * force_scale
    solver.max_it = 30
    solver.report = False
    ksp = solver.krylov_solver
    opts = PETSc.Options()
    pre = ksp.getOptionsPrefix()
    opts[f"{pre}ksp_type"] = "preonly"
    opts[f"{pre}pc_type"] = "lu"
    opts[f"{pre}pc_factor_mat_solver_type"] = "mumps"
    ksp.setFromOptions()

    def set_load(s):
        scale.value = s
        for f, value in moving:
            f.x.array[:] = s * value

    done, step, its, converged = 0.0, 1.0 / load_steps, 0, True
    backup = w.x.array.copy()
    while done < 1.0 - 1e-12:
        step = min(step, 1.0 - done)
        set_load(done + step)
        try:
            n, ok = solver.solve(w)
        except RuntimeError:
            n, ok = 0, False
        if ok and np.all(np.isfinite(w.x.array)):
            done += step
            its += n
            backup = w.x.array.copy()
            w.x.scatter_forward()
        else:
            w.x.array[:] = backup
            w.x.scatter_forward()
            step /= 2
            if step < 1.0 / 64:
                converged = False
                break

    # Independent check of the final state: the residual on the free unknowns must be small
    # against the forces the body carries (the residual on the constrained ones, the reactions).
    residual_form = fem.form(R)
    vec = fem.petsc.assemble_vector(residual_form)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    arr = vec.array.copy()
    held = np.zeros(len(arr), dtype=bool)
    for bc in bcs:
        held[bc.dof_indices()[0]] = True
    r_free = float(np.linalg.norm(arr[~held]))
    r_held = float(np.linalg.norm(arr[held]))
    if not (np.isfinite(r_free) and r_free <= 1e-8 * r_held):
        converged = False

    uh = w.sub(0).collapse()
    out = {"converged": bool(converged), "residual_free": r_free, "residual_held": r_held, "newton_iterations": int(its), "dofs": int(W.dofmap.index_map.size_global * W.dofmap.index_map_bs),
           "cells": body.n_cells, "volume_m3": body.volume, "load_reached": done}
    tree = dolfinx.geometry.BoundingBoxTree(msh, msh.topology.dim)
    for name, (point, comp) in probes.items():
        pt = np.array([point], dtype=float)
        cand = dolfinx.geometry.compute_collisions(tree, pt)
        cells = dolfinx.geometry.compute_colliding_cells(msh, cand, pt)
        c = cells.links(0)
        if len(c) == 0:
            raise ValueError(f"probe {name} at {point} lies outside the body")
        out[name] = float(np.asarray(uh.eval(pt, [c[0]])).reshape(-1)[comp])
    if reactions:
        # Reaction = residual of the unconstrained problem at the solution on the held dofs.
        for name, (marker, comp) in reactions.items():
            Vc, _ = W.sub(0).sub(comp).collapse()
            dofs = fem.locate_dofs_geometrical((W.sub(0).sub(comp), Vc), marker)[0]
            out[name] = float(-arr[dofs].sum())
    out["fe_time_s"] = time.time() - t0
    return out


def richardson(values, ratio=2.0):
    """Limit and observed order from three levels refined by `ratio` (coarse to fine). With
    non-monotone or stalled convergence the finest value is the limit and the order is None."""
    if len(values) < 3:
        return (values[-1] if values else None), None
    a, b, c = values[-3:]
    d1, d2 = b - a, c - b
    if d1 == 0 or d2 == 0 or d1 * d2 < 0:
        return c, None
    p = np.log(abs(d1 / d2)) / np.log(ratio)
    if p <= 0:
        return c, None
    return c + d2 / (ratio ** p - 1), float(p)
