// Volume preservation (docs/PHYSICS.md, "Volume preservation"): a projection onto the constraint
// V(x) = V0, with V the volume enclosed by the surface mesh (docs/SURFACE.md) whose vertices are
// surface elements. Compiled only when the scene sets [volume] preserve = true (-DVB_VOLUME=1).
// All positions are in the lattice frame (rest_position + u), where V carries det(rotation).
//
//   volume_partials: per work-group partial sums (VB_VOLUME_SLOTS reals per group)
//     0  Σ x0·(x1 × x2) over triangles (= 6V, positions relative to `centre`)
//     1  Σ w|g|² over surface elements (w = 1/m, 0 for held elements)
//     2  Σ g·v over surface elements (the rate dV/dt)
//     3  Σ |g|² over free surface elements   4  Σ g·f over free surface elements (with_force only)
//   and g = ∂V/∂x of every surface element into `grad` (indexed by element).
//   volume_finish: one work-group; scalars = {λ, μ, V, p}: λ = (V0 − V)/Σw|g|², μ = Σg·v/Σw|g|²,
//     p = Σg·f/Σ|g|² (the pressure the check subtracts from the residual).
//   volume_apply: x += λ·w·g, v −= μ·w·g on the free surface elements.
#define VB_VOLUME_SLOTS 5

inline real4 element_position(uint e, global const real4* u, global const uint* cell_of, int sy,
                              int sz, real4 origin, real h, real4 centre) {
  return rest_position(cell_of[e], sy, sz, origin, h) + xyz0(u[e]) - centre;
}

// Sums each slot of `value` over the work-group into s[k][0] (every work-item must call it).
inline void sum_over_group(local real (*s)[VB_CHECK_WG], const real* value, uint l) {
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) s[k][l] = value[k];
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = VB_CHECK_WG / 2; stride > 0; stride /= 2) {
    if (l < stride)
      for (int k = 0; k < VB_VOLUME_SLOTS; ++k) s[k][l] += s[k][l + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
}

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_partials(global const real4* u, global const real4* v, VB_LATTICE_PARAMS,
                     global const uint* triangles, uint n_triangles,
                     global const uint* surface_elements, global const uint* incident_start,
                     global const uint* incident, uint n_surface, real4 centre,
                     global real4* grad, int with_force, global real* partial) {
  local real s[VB_VOLUME_SLOTS][VB_CHECK_WG];
  const uint i = get_global_id(0), l = get_local_id(0);
  real value[VB_VOLUME_SLOTS];
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] = 0;
  if (i < n_triangles) {
    const real4 a = element_position(triangles[3 * i], u, cell_of, sy, sz, origin, h, centre);
    const real4 b = element_position(triangles[3 * i + 1], u, cell_of, sy, sz, origin, h, centre);
    const real4 c = element_position(triangles[3 * i + 2], u, cell_of, sy, sz, origin, h, centre);
    value[0] = dot3(a, cross(b, c));
  }
  if (i < n_surface) {
    const uint e = surface_elements[i];
    // ∂(x0·(x1 × x2))/∂x0 = x1 × x2, cyclically; incident[] holds 3·triangle + corner
    real4 g = 0;
    for (uint k = incident_start[i]; k < incident_start[i + 1]; ++k) {
      const uint t = incident[k] / 3, corner = incident[k] - 3 * t;
      const real4 b = element_position(triangles[3 * t + (corner + 1) % 3], u, cell_of, sy, sz, origin, h, centre);
      const real4 c = element_position(triangles[3 * t + (corner + 2) % 3], u, cell_of, sy, sz, origin, h, centre);
      g += cross(b, c);
    }
    g = xyz0(g) / (real)6;
    grad[e] = g;
    const real4 ui = u[e];
    value[1] = ui.w * dot3(g, g);
    value[2] = dot3(g, v[e]);
    if (with_force && ui.w != 0) {
      const real4 f = static_force(e, ui, v[e], u, v, VB_LATTICE_ARGS);
      value[3] = dot3(g, g);
      value[4] = dot3(g, f);
    }
  }
  sum_over_group(s, value, l);
  if (l == 0)
    for (int k = 0; k < VB_VOLUME_SLOTS; ++k) partial[get_group_id(0) * VB_VOLUME_SLOTS + k] = s[k][0];
}

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_finish(global const real* partial, uint groups, real rest_volume, global real* scalars) {
  local real s[VB_VOLUME_SLOTS][VB_CHECK_WG];
  const uint l = get_local_id(0);
  real value[VB_VOLUME_SLOTS];
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] = 0;
  for (uint g = l; g < groups; g += VB_CHECK_WG)
    for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] += partial[g * VB_VOLUME_SLOTS + k];
  sum_over_group(s, value, l);
  if (l == 0) {
    const real volume = s[0][0] / (real)6, wgg = s[1][0], gg = s[3][0];
    scalars[0] = wgg > 0 ? (rest_volume - volume) / wgg : 0;  // λ
    scalars[1] = wgg > 0 ? s[2][0] / wgg : 0;                  // μ
    scalars[2] = volume;
    scalars[3] = gg > 0 ? s[4][0] / gg : 0;                    // p
  }
}

kernel void volume_apply(global real4* u, global real4* v, global const uint* surface_elements,
                         uint n_surface, global const real4* grad, global const real* scalars) {
  const uint i = get_global_id(0);
  if (i >= n_surface) return;
  const uint e = surface_elements[i];
  const real4 ui = u[e];
  if (ui.w == 0) return;
  const real4 wg = ui.w * grad[e];
  u[e] = ui + scalars[0] * wg;
  v[e] = v[e] - scalars[1] * wg;
}
