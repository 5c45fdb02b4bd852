// Indenter contact with the surface triangles (`[[indenter]] contact_surface = "triangles"`,
// docs/PROBING.md): a penalty force at the point of each surface triangle nearest the indenter,
// split to the triangle's three vertex elements by the barycentric weights of that point (the
// haptic paper's point probe, 003_ed66fc07f16d222f.txt). Two passes, no float atomics:
//   triangle_contact: one work-item per triangle writes, per indenter, its three corner forces;
//   triangle_contact_force: each element sums the corners it is (CSR tri_start / tri_corner).
//   -DVB_TRI_CONTACT=0|1  some indenter uses it (nothing here is compiled otherwise)
//   -DVB_TRI_FP64=0|1     the penalty's geometry in double (float models on fp64 devices)
// Indenter row columns (kernels/common.cl): 17 Coulomb μ, 18 contact surface (0 vertices,
// 1 triangles), 19 penalty stiffness k_p (N/m).
#if VB_TRI_CONTACT
#define VB_TRI_PARAMS \
  , global const real4 *corner_force, global const uint *tri_start, global const uint *tri_corner, uint n_tri
#define VB_TRI_ARGS , corner_force, tri_start, tri_corner, n_tri

inline int uses_triangles(global const real* ind) { return ind[18] != 0; }

// The penalty's gap r − |p − c| comes from absolute positions (tens of mm): in float their
// rounding (~4e-9 m) times k_p is a force noise of ~2e-5·E·h² per element, which stalled float
// relaxations there (docs/VALIDATION.md, "Probing: palpation and indenters"). On an fp64 device the geometry is computed in
// double (the state stays float), which removes that noise; the pass is per surface triangle, cheap.
#if VB_TRI_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double tri_real;
typedef double4 tri_real4;
#define TRI_REAL4(v) convert_double4(v)
#else
typedef real tri_real;
typedef real4 tri_real4;
#define TRI_REAL4(v) (v)
#endif

inline tri_real tri_dot3(tri_real4 a, tri_real4 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Barycentric weights (w_a, w_b, w_c, 0) of the point of triangle (a, b, c) nearest p and its
// feature: 0 the face, 1–3 vertex a, b, c, 4–6 edge ab, bc, ca (Ericson, Real-Time Collision
// Detection, §5.1.5: Voronoi regions of the features, tested in turn).
inline tri_real4 nearest_on_triangle(tri_real4 p, tri_real4 a, tri_real4 b, tri_real4 c, int* feature) {
  const tri_real4 ab = b - a, ac = c - a, ap = p - a;
  const tri_real d1 = tri_dot3(ab, ap), d2 = tri_dot3(ac, ap);
  if (d1 <= 0 && d2 <= 0) { *feature = 1; return (tri_real4)(1, 0, 0, 0); }
  const tri_real4 bp = p - b;
  const tri_real d3 = tri_dot3(ab, bp), d4 = tri_dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) { *feature = 2; return (tri_real4)(0, 1, 0, 0); }
  const tri_real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const tri_real v = d1 / (d1 - d3);
    *feature = 4;
    return (tri_real4)(1 - v, v, 0, 0);
  }
  const tri_real4 cp = p - c;
  const tri_real d5 = tri_dot3(ab, cp), d6 = tri_dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) { *feature = 3; return (tri_real4)(0, 0, 1, 0); }
  const tri_real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const tri_real w = d2 / (d2 - d6);
    *feature = 6;
    return (tri_real4)(1 - w, 0, w, 0);
  }
  const tri_real va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const tri_real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    *feature = 5;
    return (tri_real4)(0, 1 - w, w, 0);
  }
  const tri_real denom = 1 / (va + vb + vc);
  const tri_real v = vb * denom, w = vc * denom;
  *feature = 0;
  return (tri_real4)(1 - v - w, v, w, 0);
}

// Every triangle the sphere overlaps (its nearest point p within r) pushes on its own: a penalty
// potential ½·k_p·depth² per triangle, smooth in the vertex positions, so the total force is
// continuous as the contact moves over faces, edges and vertices (a contact at a shared edge or
// vertex is felt by each triangle there: the penalty is up to that many times stiffer there, the
// force still the tissue's; docs/PROBING.md). In front of the face the penetration is r − |p − c|
// along (p − c)/|p − c|; a centre that has passed behind a face pushes along the inward normal
// with r + |p − c| (the force keeps growing: a probe pressed in increments below its radius cannot
// slip through). The force k_p·depth·n (on the tissue) goes to the corners by weight.
kernel void triangle_contact(global const real4* u, global const uint* cell_of, int sy, int sz, real4 origin,
                             real h, global const uint* triangles, uint n_triangles, real frame_sign,
                             global const real* indenters, real t, global real4* corner_out) {
  const uint tr = get_global_id(0);
  if (tr >= n_triangles) return;
  tri_real4 x[3];
  for (int k = 0; k < 3; ++k) {
    const uint e = triangles[3 * tr + k];
    x[k] = TRI_REAL4(rest_position(cell_of[e], sy, sz, origin, h)) + TRI_REAL4(xyz0(u[e]));
  }
  const tri_real4 normal = (tri_real)frame_sign * cross(x[1] - x[0], x[2] - x[0]);  // outward (lattice frame)
  const tri_real normal_len = length(normal);
  const tri_real4 outward = normal_len > 0 ? normal / normal_len : (tri_real4)(0);
  for (int i = 0; i < VB_INDENTERS; ++i) {
    global const real* ind = indenters + VB_IND_STRIDE * i;
    tri_real4 force = (tri_real4)(0), w = (tri_real4)(0);
    if (uses_triangles(ind)) {
      const tri_real4 c = TRI_REAL4(indenter_position(ind, t));
      int feature;
      w = nearest_on_triangle(c, x[0], x[1], x[2], &feature);
      const tri_real4 p = w.x * x[0] + w.y * x[1] + w.z * x[2];
      const tri_real4 d = p - c;
      const tri_real dist = length(d), r = ind[3];
      if (dist < r) {
        const int behind = feature == 0 && tri_dot3(d, outward) > 0;  // centre behind the face
        const tri_real depth = behind || dist == 0 ? r + dist : r - dist;
        const tri_real4 n = behind || dist == 0 ? -outward : d / dist;
        force = (tri_real)ind[19] * depth * n;
      }
    }
    global real4* out = corner_out + 3 * ((size_t)i * n_triangles + tr);
#if VB_TRI_FP64
    out[0] = (real4)((real)(w.x * force.x), (real)(w.x * force.y), (real)(w.x * force.z), 0);
    out[1] = (real4)((real)(w.y * force.x), (real)(w.y * force.y), (real)(w.y * force.z), 0);
    out[2] = (real4)((real)(w.z * force.x), (real)(w.z * force.y), (real)(w.z * force.z), 0);
#else
    out[0] = w.x * force;
    out[1] = w.y * force;
    out[2] = w.z * force;
#endif
  }
}

// Force of triangle-contact indenter i on element e (N): the sum of the corners it is.
inline real4 triangle_contact_force(uint e, int i, global const real4* corner_force, global const uint* tri_start,
                                    global const uint* tri_corner, uint n_tri) {
  real4 f = (real4)(0);
  global const real4* forces = corner_force + 3 * (size_t)i * n_tri;
  for (uint k = tri_start[e]; k < tri_start[e + 1]; ++k) f += forces[tri_corner[k]];
  return xyz0(f);
}

// All triangle-contact indenters' forces on element e (N) at time t. With friction (VB_FRICTION,
// column 17 μ > 0) each indenter's gathered force f on the element, its share of the touching
// triangles' penalty forces (all along their normals), is the element's normal force: it adds
// μ·|f| to the element's grip with the normal f/|f| and the indenter's velocity
// (device_contact.cl: Coulomb stick/slip at the velocity level, as for vertex contact). The sum
// is formed the same way with or without friction (μ = 0: the frictionless result bit for bit).
inline real4 triangle_contact_all(uint e, global const real* indenters, real t, torus_grip* grip,
                                  global const real4* corner_force, global const uint* tri_start,
                                  global const uint* tri_corner, uint n_tri) {
  real4 f = (real4)(0);
  for (int i = 0; i < VB_INDENTERS; ++i) {
    global const real* ind = indenters + VB_IND_STRIDE * i;
    if (!uses_triangles(ind)) continue;
    const real4 pushed = triangle_contact_force(e, i, corner_force, tri_start, tri_corner, n_tri);
    f += pushed;
#if VB_FRICTION
    const real fn = length(pushed);
    if (fn > 0) grip_add(grip, -fn, ind[17], pushed / fn, indenter_velocity(ind, t));
#endif
  }
  return f;
}
#else
#define VB_TRI_PARAMS
#define VB_TRI_ARGS
#endif
