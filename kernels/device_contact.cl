// Pneumatic torus device (docs/PHYSICS.md, "Torus device"): rigid tori whose minor and major
// radii follow a piecewise-linear inflation schedule, pushing the elements they touch the way
// push indenters do (kernels/lattice_forces.cl), optionally with Coulomb friction.
//   -DVB_TORI=count       number of tori (0: nothing here is compiled but the no-op grip)
//   -DVB_TORUS_BASE=N     offset (reals) of the first torus row in the rigid-obstacle table
//                         (the `indenters` argument: indenter rows, then torus rows, then knots)
//   -DVB_FRICTION=0|1     some torus or indenter has friction (the grip helpers serve both)
// Torus row (lattice frame, VB_TORUS_STRIDE reals): 0–2 centre (m), 3 friction coefficient μ,
// 4–6 unit axis, 7 knot count K, 8–10 a unit vector ⟂ axis (the radial direction on the axis),
// 11 offset of its knots in the table: K rows of VB_KNOT_STRIDE reals: time t_i (s), minor and major
// radius (m), 1/(t_{i+1} − t_i) (1/s), the segment's dr/dt and dR/dt (m/s); the last row's three
// segment values are 0.
#define VB_TORUS_STRIDE 12
#define VB_KNOT_STRIDE 6
// Inlined whatever the compiler's cost model says: a call per element and torus (passing the normal
// through memory) costs PoCL more than the arithmetic.
#define VB_INLINE inline __attribute__((always_inline))

// Friction of an element touching a torus during one stage: μ·|f_n| the contact can resist
// tangentially (N, or m/s² when the constraint works on the acceleration f/m), the contact
// normal and the surface's velocity there. grip_n = 0: no friction.
typedef struct {
  real grip_n;
  real4 normal;
  real4 surface_v;
} torus_grip;

// Coulomb friction shared by the torus device and the push indenters (lattice_forces.cl): a
// contact that carries `push` (≤ 0: its normal force or acceleration along n) with coefficient mu
// adds mu·|push| to the grip; the last gripping contact gives the normal and surface velocity.
VB_INLINE void grip_add(torus_grip* g, real push, real mu, real4 n, real4 surface_v) {
#if VB_FRICTION
  const int gripping = push < 0 && mu > 0;
  g->grip_n -= gripping ? push * mu : (real)0;
  g->normal = gripping ? n : g->normal;
  g->surface_v = gripping ? surface_v : g->surface_v;
#endif
}

// The part of an inward normal force or acceleration fn (< 0) that a push contact carries, shared
// by the torus device and the push indenters (lattice_forces.cl). In a stage the element, at
// distance dist outside the surface and moving at vn along n relative to it, ends near
// dist + lead·vn + gain·(fn − carried): it keeps what brings it at most onto the surface, and the
// contact carries the rest. Without that rule, an element whose free equilibrium lay inside the
// contact band coasted out to the band's edge with its restoring force removed and fell back, a
// cycle that never settled (docs/PHYSICS.md, "Indenters", landing rule). A distance within `res`
// (contact_resolution) of zero counts as on the surface: the stage then only stops the normal
// motion. gain 0 (a check, after which no stage follows): the contact carries all of fn.
VB_INLINE real push_carried(real fn, real dist, real vn, real lead, real gain, real res) {
  if (!(gain > 0)) return fn;
  const real off = fabs(dist) <= res ? (real)0 : dist;
  const real land = -(off + lead * vn) / gain;  // lands on the surface at the stage's end
  return fn - fmin((real)0, fmax(fn, land));
}

// At a check: the tangential part of f (to n) that friction holds, at most mu·fn (fn ≥ 0, the
// compressive normal force); removed from f and returned (the contact carries it).
VB_INLINE real4 friction_hold(real4* f, real4 n, real fn, real mu) {
  const real4 ft = *f - dot3(*f, n) * n;
  const real size = length(ft), limit = mu * fn;
  const real4 held = size <= limit ? ft : ft * (limit / size);
  *f -= held;
  return held;
}

// At a check, for an indenter: the friction force a contact carries (removed from f, returned:
// the force on the indenter). An element that slides over the surface (tangential speed relative
// to it above `slip`, m/s) carries the kinetic friction μ·fn along its slip: what the steps'
// grip applies to it, whatever its own tangential force is at this instant (a sliding element's
// spring force swings about μ·fn as it slides; capping it at μ·fn, as for one at rest, reads the
// swings short: docs/VALIDATION.md, "Contact with devices", friction). One at rest on the surface (the grip
// stopped it) carries its tangential force up to μ·fn (friction_hold).
VB_INLINE real4 friction_carried(real4* f, real4 n, real fn, real mu, real4 v_rel, real slip) {
  const real4 vt = xyz0(v_rel) - dot3(v_rel, n) * n;
  const real speed = length(vt);
  if (!(speed > slip)) return friction_hold(f, n, fn, mu);
  const real4 held = (mu * fn / speed) * vt;
  *f -= held;
  return held;
}

#if VB_TORI
VB_INLINE global const real* torus_row(global const real* table, int i) {
  return table + VB_TORUS_BASE + VB_TORUS_STRIDE * i;
}

// (r, R, dr/dt, dR/dt) at time t: linear between knots, held before the first and after the last.
VB_INLINE real4 torus_radii(global const real* table, global const real* tor, real t) {
  const int K = (int)tor[7];
  global const real* k = table + (int)tor[11];
  real4 out = (real4)(k[1], k[2], 0, 0);
  for (int i = 0; i + 1 < K; ++i) {  // each segment adds its share: the sum telescopes
    global const real* a = k + VB_KNOT_STRIDE * i;
    global const real* b = a + VB_KNOT_STRIDE;
    const real s = clamp((t - a[0]) * a[3], (real)0, (real)1);
    const real on = t >= a[0] && t < b[0] ? (real)1 : (real)0;
    out += (real4)(s * (b[1] - a[1]), s * (b[2] - a[2]), on * a[4], on * a[5]);
  }
  return out;
}

// Whether x may be within `margin` of the tube (cheap, no square root): inside the slab
// |z| ≤ r + margin and the annulus R − r − margin ≤ ρ ≤ R + r + margin. Elements far from every
// tube (most of them) skip the distance.
VB_INLINE int torus_near(real4 x, global const real* tor, real4 rad, real margin) {
  const real4 a = (real4)(tor[4], tor[5], tor[6], 0);
  const real4 q = (real4)(x.x - tor[0], x.y - tor[1], x.z - tor[2], 0);
  const real z = dot3(q, a), reach = rad.x + margin;
  const real rho_sq = dot3(q, q) - z * z, inner = fmax(rad.y - reach, (real)0), outer = rad.y + reach;
  return fabs(z) <= reach && rho_sq >= inner * inner && rho_sq <= outer * outer;
}

// Signed distance from the tube surface of radii `rad` (torus_radii) (m, < 0 inside), the
// outward unit normal and the surface's velocity at the nearest surface point (m/s: dr/dt along
// n, dR/dt radially).
VB_INLINE real torus_distance_at(real4 x, global const real* tor, real4 rad, real4* n_out, real4* w_out) {
  const real4 a = (real4)(tor[4], tor[5], tor[6], 0);
  const real4 q = (real4)(x.x - tor[0], x.y - tor[1], x.z - tor[2], 0);
  const real z = dot3(q, a);
  const real4 p = q - z * a;
  const real rho = length(p);
  const real4 e = rho > 0 ? p / rho : (real4)(tor[8], tor[9], tor[10], 0);
  const real dx = rho - rad.y;
  const real d = sqrt(dx * dx + z * z);
  *n_out = d > 0 ? (dx * e + z * a) / d : e;
  *w_out = rad.w * e + rad.z * *n_out;
  return d - rad.x;
}

VB_INLINE real torus_distance(real4 x, global const real* table, global const real* tor, real t, real4* n_out,
                              real4* w_out) {
  return torus_distance_at(x, tor, torus_radii(table, tor, t), n_out, w_out);
}

// Frictionless unilateral contact of an element within REAL_CONTACT_TOL·h of the tube surface (or
// inside): the torus carries the inward normal part of f (a force, or the acceleration f/m: the
// same constraint) that would take the element into the tube (push_carried: the element at x with
// velocity v ends its stage near x + lead·v + gain·a), which is removed from f and returned (the
// force on the torus, N, for a force). With friction, μ·|f_n| is added to the grip.
VB_INLINE real4 torus_constrain(real4* f, real4 x, real4 v, real lead, real gain, global const real* table,
                                global const real* tor, real t, real h, torus_grip* grip) {
  const real4 rad = torus_radii(table, tor, t);
  if (!torus_near(x, tor, rad, REAL_CONTACT_TOL * h)) return (real4)(0);
  real4 n, w;
  const real dist = torus_distance_at(x, tor, rad, &n, &w);
  const real fn = dot3(*f, n);
  const real push =
      dist <= REAL_CONTACT_TOL * h && fn < 0 ? push_carried(fn, dist, dot3(v - w, n), lead, gain, contact_resolution(x))
                                             : (real)0;  // ≤ 0
  *f -= push * n;
  grip_add(grip, push, tor[3], n, w);
  return push * n;
}

VB_INLINE void torus_constrain_all(real4* f, real4 x, real4 v, real lead, real gain, global const real* table, real t,
                                   real h, torus_grip* grip) {
  for (int i = 0; i < VB_TORI; ++i) torus_constrain(f, x, v, lead, gain, table, torus_row(table, i), t, h, grip);
}

// Moves an element that ended a stage inside a tube (deeper than contact_resolution) back onto its
// surface; its normal velocity becomes at least the surface's (an inflating tube pushes it out at
// dr/dt).
VB_INLINE void torus_project_all(real4* ui, real4* vi, real4 X, global const real* table, real t, real h) {
  for (int i = 0; i < VB_TORI; ++i) {
    global const real* tor = torus_row(table, i);
    const real4 rad = torus_radii(table, tor, t), x = X + xyz0(*ui);
    if (!torus_near(x, tor, rad, REAL_CONTACT_TOL * h)) continue;
    real4 n, w;
    const real dist = torus_distance_at(x, tor, rad, &n, &w);
    const int inside = dist < -contact_resolution(x);
    *ui -= (inside ? dist : (real)0) * n;
    const real vn = dot3(*vi, n), wn = dot3(w, n);
    *vi += (inside && vn < wn ? wn - vn : (real)0) * n;
  }
}
#endif

// Coulomb friction at the velocity level: the stage's tangential impulse per unit mass is at most
// μ·|a_n|·dt, so the tangential velocity relative to the surface drops by at most that. An element
// whose tangential force stays within μ·|f_n| is stopped (sticks); beyond, it slides with friction
// μ·|f_n| against its motion. `g` was collected on the acceleration; `dt` is the stage's.
VB_INLINE void torus_apply_grip(real4* v, torus_grip g, real dt) {
#if VB_FRICTION
  const real4 rel = xyz0(*v - g.surface_v);
  const real4 vt = rel - dot3(rel, g.normal) * g.normal;
  const real speed = length(vt), stop = g.grip_n * dt;  // no grip: stop = 0, nothing removed
  *v -= (speed > stop ? stop / speed : (real)1) * vt;
#endif
}
