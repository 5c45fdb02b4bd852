"""The cross-check cases: each gives VoxBreast's scene at a spacing and the same problem for FE.

Element centres lie on the global (n + 1/2) h grid. Every case is written in integer element
positions n (centre (n + 1/2) h), so the FE body, the union of the dual cells of those elements,
is exactly VoxBreast's elastic body for hyperelastic tissue, and the held layer of centres is the
FE's held face.
"""

import numpy as np

from hull import hull_elements

G = 9.81  # m/s^2


def neo_hookean(E, nu):
    """(mu, kappa) of VoxBreast's neo-Hookean tissue from E and nu (PHYSICS.md section 3)."""
    return E / (2 * (1 + nu)), E / (3 * (1 - 2 * nu))


def material_toml(name, law, E, nu, rho):
    lines = [f"[materials.{name}]", f'law = "{law}"', f"E = {E!r}", f"density = {rho!r}"]
    if law != "linear":
        lines.append(f"nu = {nu!r}")
    return "\n".join(lines) + "\n"


def solver_toml(precision, tol, max_steps):
    return (f'[solver]\nintegrator = "relaxation"\nprecision = "{precision}"\ncheck_every = 10\n\n'
            f"[stop]\nequilibrium = {tol!r}\nmax_steps = {max_steps}\n")


def box_toml(size):
    """A box from the origin to size on each axis: element centres at (n + 1/2) h inside it."""
    return f"kind = \"box\"\nmin = [0, 0, 0]\nmax = {vec([size] * 3)}\n"


def vec(v):
    return "[" + ", ".join(f"{x:.12g}" for x in v) + "]"


class Case:
    """Base: a body of tissue 'tissue' with one material, gravity, a held layer, one probe."""
    laws = ("neo-hookean",)
    float_tol = 1e-5  # stop.equilibrium of float runs: above float's rounding floor (SCENE.md)
    float_min_h = 0.0  # float runs below this spacing (m) are not made (they stall at their floor)
    fe_body_depends_on_h = True

    def scene_text(self, h, shape, law, precision, tol, max_steps, loads):
        """A scene of one tissue: the shape's TOML lines, the material, the solver, then loads."""
        return (f"[model]\nspacing = {h!r}\n\n[[model.shape]]\n{shape}label = \"tissue\"\n\n"
                + material_toml("tissue", law, self.E, self.nu, self.rho)
                + "\n" + solver_toml(precision, tol, max_steps) + "\n" + loads)

    def held_under_gravity(self, gravity, anchor_point, anchor_normal, probe):
        """Loads of the gravity cases: gravity, the held layer (a half-space), the probe."""
        return (f"[gravity]\nvector = {vec(gravity)}\n\n"
                f"[anchor.base]\nkind = \"halfspace\"\npoint = {vec(anchor_point)}\nnormal = {vec(anchor_normal)}\n\n"
                f"[[track]]\nname = \"probe\"\npoint = {vec(probe)}\n")

    def fe_material(self, points):
        return np.zeros(len(points), dtype=int)

    def fe_materials(self):
        return [neo_hookean(self.E, self.nu)]

    def fe_density(self, points):
        return np.full(len(points), self.rho)


class CubeSag(Case):
    """A cube of hull side L (element centres L/h + 1 per edge), its bottom layer held, sagging
    under its own weight. Quantity: the downward displacement of the top face's centre."""
    fe_body_depends_on_h = False

    def __init__(self, name, L, E, nu, rho=1000.0, gscale=1.0, laws=("neo-hookean",), float_tol=1e-5,
                 float_min_h=0.0):
        self.name, self.L, self.E, self.nu, self.rho, self.g = name, L, E, nu, rho, G * gscale
        self.laws, self.float_tol, self.float_min_h = laws, float_tol, float_min_h
        self.quantity = "sag_mm"
        self.description = (f"cube {L*1e3:g} mm, bottom held, self-weight {self.g:.3g} m/s², "
                            f"E {E:g} Pa, ν {nu:g}")

    def n(self, h):
        n = round(self.L / h) + 1
        if abs((n - 1) * h - self.L) > 1e-9 or n % 2 == 0:
            raise ValueError(f"{self.name}: L = {self.L} is not an even number of spacings {h}")
        return n

    def scene(self, h, law, precision, tol, max_steps):
        n = self.n(h)
        c = n * h / 2
        loads = self.held_under_gravity([0, 0, -self.g], [0, 0, 0.75 * h], [0, 0, -1], [c, c, (n - 0.5) * h])
        return self.scene_text(h, box_toml(n * h), law, precision, tol, max_steps, loads)

    def from_summary(self, summary):
        return -summary["tracked"]["probe"]["displacement_m"][2] * 1e3

    def fe_problems(self, h, levels):
        """FE levels: the cube meshed with N dual cells per edge (N in levels), h-independent."""
        for N in levels:
            hf = self.L / N
            ijk = np.array([(i, j, k) for i in range(N + 1) for j in range(N + 1) for k in range(N + 1)])
            lo, hi = 0.5 * hf, self.L + 0.5 * hf
            mid = 0.5 * (lo + hi)
            yield N, ijk, hf, 1, dict(
                gravity=[0.0, 0.0, -self.g],
                fixed=lambda x, lo=lo: np.isclose(x[2], lo),
                sliding=[], probes={"u": ([mid, mid, hi], 2)})

    def from_fe(self, out):
        return -out["u"] * 1e3


class Hemisphere(Case):
    """A hemisphere of radius R hanging from its base (held), loaded by its weight along its axis
    or sideways. Element positions n with |n|^2 <= (R/h)^2 and n_z <= 0 around the base centre's
    element (placed at index 0); the hull differs with h, so FE solves each spacing's body."""

    def __init__(self, name, R, E, nu, sideways, rho=1000.0):
        self.name, self.R, self.E, self.nu, self.rho, self.sideways = name, R, E, nu, rho, sideways
        self.quantity = "apex_sideways_mm" if sideways else "sag_mm"
        self.description = (f"hemisphere R {R*1e3:g} mm hanging from its base, weight "
                            f"{'sideways' if sideways else 'along the axis'}, E {E:g} Pa, ν {nu:g}")

    def ijk(self, h):
        m = round(self.R / h)
        if abs(m * h - self.R) > 1e-9:
            raise ValueError(f"{self.name}: R is not a whole number of spacings {h}")
        r = np.arange(-m, m + 1)
        i, j, k = np.meshgrid(r, r, np.arange(-m, 1), indexing="ij")
        keep = i * i + j * j + k * k <= m * m
        return np.stack([i[keep], j[keep], k[keep]], axis=1)

    def probe(self, h):
        """The lowest point of the body on its axis: the lowest element on the axis that is a
        corner of a complete dual cell (the tip element itself may be in none)."""
        ijk = hull_elements(self.ijk(h))
        on_axis = ijk[(ijk[:, 0] == 0) & (ijk[:, 1] == 0)]
        k = on_axis[:, 2].min()
        return [0.5 * h, 0.5 * h, (k + 0.5) * h]

    def gravity(self):
        return [G, 0.0, 0.0] if self.sideways else [0.0, 0.0, -G]

    def scene(self, h, law, precision, tol, max_steps):
        delta = 1e-4 * h  # the base layer and the rim lie exactly on the shape: keep them inside
        c = [0.5 * h, 0.5 * h, 0.5 * h + delta]
        shape = f"kind = \"hemisphere\"\ncenter = {vec(c)}\nradius = {self.R + 2*delta!r}\naxis = [0, 0, -1]\n"
        loads = self.held_under_gravity(self.gravity(), [0, 0, 0.25 * h], [0, 0, 1], self.probe(h))
        return self.scene_text(h, shape, law, precision, tol, max_steps, loads)

    def from_summary(self, summary):
        d = summary["tracked"]["probe"]["displacement_m"]
        return (d[0] if self.sideways else -d[2]) * 1e3

    def fe_problems(self, h, levels):
        ijk = self.ijk(h)
        apex = self.probe(h)
        for r in levels:
            yield r, ijk, h, r, dict(
                gravity=self.gravity(),
                fixed=lambda x, h=h: np.isclose(x[2], 0.5 * h),
                sliding=[], probes={"u": (apex, 0 if self.sideways else 2)})

    def from_fe(self, out):
        return (out["u"] if self.sideways else -out["u"]) * 1e3


class ConfinedCompression(Case):
    """A cube in a frictionless box (base and four side plates fixed), its top plate pressed down
    by a strain eps. The deformation is homogeneous, F = diag(1, 1, 1 - eps), so the force has a
    closed form, P_zz * L^2 with P_zz = dW/dlambda; FE checks the same on a coarse mesh.
    Quantity: the top plate's force (N)."""
    fe_body_depends_on_h = False

    def __init__(self, name, L, E, nu, eps, rho=1000.0, float_tol=1e-5):
        self.name, self.L, self.E, self.nu, self.eps, self.rho = name, L, E, nu, eps, rho
        self.float_tol = float_tol
        self.quantity = "force_mN"
        self.description = f"confined compression {eps*100:g}%, cube {L*1e3:g} mm, E {E:g} Pa, ν {nu:g}"

    def closed_form_mN(self):
        mu, kappa = neo_hookean(self.E, self.nu)
        lam = 1 - self.eps
        dW = mu / 2 * (-2.0 / 3.0 * lam ** (-5.0 / 3.0) * (2 + lam * lam) + 2 * lam ** (1.0 / 3.0)) + kappa * (lam - 1)
        return -dW * self.L ** 2 * 1e3

    def scene(self, h, law, precision, tol, max_steps):
        n = round(self.L / h) + 1
        lo, hi = 0.5 * h, (n - 0.5) * h
        travel = 0.1
        plates = ""
        for axis in range(3):
            for side, pos in ((1, lo), (-1, hi)):
                start, normal = [0.0, 0.0, 0.0], [0, 0, 0]
                start[axis], normal[axis] = pos, side
                plates += f"[[indenter]]\nkind = \"plate\"\nstart = {vec(start)}\nnormal = {vec(normal)}\n"
                if axis == 2 and side == -1:
                    plates += f"velocity = [0, 0, {-self.eps*self.L/travel!r}]\ntravel_time = {travel!r}\n"
                plates += "\n"
        return self.scene_text(h, box_toml(n * h), law, precision, tol, max_steps, plates)

    def from_summary(self, summary):
        return summary["indenters"][5]["reaction_force_n"][2] * 1e3

    def fe_problems(self, h, levels):
        for N in levels:
            hf = self.L / N
            ijk = np.array([(i, j, k) for i in range(N + 1) for j in range(N + 1) for k in range(N + 1)])
            lo, hi = 0.5 * hf, self.L + 0.5 * hf
            sl = [(lambda x, a=a, v=v: np.isclose(x[a], v), a, 0.0) for a in range(3) for v in (lo, hi) if not (a == 2 and v == hi)]
            sl.append((lambda x, hi=hi: np.isclose(x[2], hi), 2, -self.eps * self.L))
            yield N, ijk, hf, 1, dict(
                gravity=[0.0, 0.0, 0.0], fixed=None, sliding=sl, probes={},
                reactions={"f": (lambda x, hi=hi: np.isclose(x[2], hi), 2)})

    def from_fe(self, out):
        return out["f"] * 1e3


def all_cases():
    return {c.name: c for c in [
        CubeSag("cube_sag", 0.024, 1000.0, 0.45),
        CubeSag("cube_sag_small", 0.024, 30000.0, 0.25, laws=("neo-hookean", "linear"), float_tol=1e-6),
        CubeSag("cube_sag_nu049", 0.024, 1000.0, 0.49, float_min_h=0.002),
        CubeSag("cube_sag_nu0499", 0.024, 1000.0, 0.499, float_tol=1e-4, float_min_h=0.002),
        Hemisphere("hemisphere_axial", 0.016, 2000.0, 0.45, sideways=False),
        Hemisphere("hemisphere_sideways", 0.016, 2000.0, 0.45, sideways=True),
        ConfinedCompression("confined_nu049", 0.008, 1000.0, 0.49, 0.1),
        ConfinedCompression("confined_nu0499", 0.008, 1000.0, 0.499, 0.1, float_tol=1e-4),
    ]}
