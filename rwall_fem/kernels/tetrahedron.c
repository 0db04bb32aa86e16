/* Internal force of the P1 (constant-strain) tetrahedron.
 *
 * With d_k = x_k - x_0 (k = 1, 2, 3) and det = d_1 . (d_2 x d_3), the shape
 * function gradients are grad N_1 = d_2 x d_3 / det, grad N_2 = d_3 x d_1 / det,
 * grad N_3 = d_1 x d_2 / det, grad N_0 = -(grad N_1 + grad N_2 + grad N_3), and
 * the volume is |det| / 6 (either vertex orientation).  One integration point
 * is exact for P1: f_I = V T(grad u) grad N_I (materials.h).  In isochoric
 * plastic flow constant-strain tetrahedra lock (one volume constraint per cell):
 * prefer hexahedra there (docs/theory.md).
 */
#include "failure.h"
#include "materials.h"

/* Shape function gradients g[I] (1/m) and volume (m^3) of the tetrahedra at x[3 I + i];
 * *det the signed 6 V (positive for the orientation of elasto-plastic cells). */
INLINE vec tet4_geometry_signed(const vec *restrict x, vec g[4][3], vec *det_out)
{
  vec d[3][3];
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 3; ++i)
      d[a][i] = x[3 * (a + 1) + i] - x[i];
  cross(d[1], d[2], g[1]);
  cross(d[2], d[0], g[2]);
  cross(d[0], d[1], g[3]);
  const vec det = dot3(d[0], g[1]), inv_det = 1.0 / det;
  for (int i = 0; i < 3; ++i)
  {
    g[1][i] *= inv_det;
    g[2][i] *= inv_det;
    g[3][i] *= inv_det;
    g[0][i] = -(g[1][i] + g[2][i] + g[3][i]);
  }
  *det_out = det;
  return (1.0 / 6.0) * vabs(det);
}

INLINE vec tet4_geometry(const vec *restrict x, vec g[4][3])
{
  vec det;
  return tet4_geometry_signed(x, g, &det);
}

/* L = sum_I w_I (x) g_I for nodal vectors w[3 I + i]. */
INLINE void tet4_gradient(const vec *restrict w, vec g[4][3], vec L[9])
{
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      L[3 * i + j] = w[i] * g[0][j] + w[3 + i] * g[1][j] + w[6 + i] * g[2][j] + w[9 + i] * g[3][j];
}

/* f_I = V T g_I */
INLINE void tet4_nodal_forces(vec volume, const vec T[9], vec g[4][3], vec *restrict f)
{
  for (int I = 0; I < 4; ++I)
    for (int i = 0; i < 3; ++i)
      f[3 * I + i] = volume * (T[3 * i] * g[I][0] + T[3 * i + 1] * g[I][1] + T[3 * i + 2] * g[I][2]);
}

/* The nodal forces f[3 I + i] of a batch; returns the stored energy of each cell, and in
 * *jacobian det(I + grad u), in *modulus rho_0 c^2 (Pa, when p->estimate). */
INLINE vec tet4_cell(int model, const vec *restrict x, const vec *restrict u, vec *restrict f,
                     const element_params *p, vec *jacobian, vec *modulus)
{
  vec g[4][3], L[9], T[9];
  const vec volume = tet4_geometry(x, g);
  tet4_gradient(u, g, L);
  const vec w = volume * stress(model, L, p->lmbda, p->mu, T);
  tet4_nodal_forces(volume, T, g, f);
  *jacobian = volume_ratio(L);
  if (p->estimate)
    *modulus = wave_modulus(model, L, p->lmbda, p->mu);
  return w;
}

/* Total Lagrangian tetrahedra: the stable step of a cell is L_0 / c with its length at
 * rest and the wave speed of the law at its strain (step.h); erosion as failure.h says. */
INLINE void tet4_force(int model, int64_t num_cells, const int32_t *restrict cells,
                       const double *restrict X, const double *restrict u,
                       const element_params *p, double *restrict f, double *restrict energy,
                       double *restrict step)
{
  vec x[12], ue[12], fe[12], jacobian, modulus;
  double total = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 4, &b, X, x);
    gather(cells, 4, &b, u, ue);
    const vec w = tet4_cell(model, x, ue, fe, p, &jacobian, &modulus);
    const ivec inverted = jacobian <= 0.0;
    vec dte = VZERO + INFINITY;
    if (p->estimate)
      dte = p->calibration * cell_values(p->length0, &b) * vsqrt(p->density / modulus);
    const ivec failed = failed_lanes(p, VZERO, inverted, dte, w);
    if (any_lane(failed))
    {
      vec du[12];
      increments(p, cells, 4, &b, du);
      erode(p, failed, &b, energy_left(w, du, fe, 4), VZERO, VZERO, fe, 4, energy, step);
    }
    total += lane_sum(vselect(failed, VZERO, w), b.nb);
    add_batch(p, cells, 4, &b, inverted, failed, dte, x, ue, fe, f, step);
  }
  energy[0] += total;
}

/* Elasto-plastic tetrahedra (updated Lagrangian, plasticity.h): the increment du = dt v
 * (dt = 0 at the first step: the state is the initial one) has its gradient taken in the
 * mid-step configuration; the force is that of the updated stress in the current one,
 * x = X + u.  energy[0] += stored elastic energy, energy[2] += plastic dissipation of the
 * step (J); a cell is inverted when its volume is not positive (the cells are oriented
 * positively at the start), and its stable step is L / c in the current configuration,
 * c from the elastic moduli and the current density (step.h).  state: POINT_SLOTS rows
 * of `stride` values, and the damage row of failure.h, which also says how cells fail
 * and are eroded. */
void tet4_plastic(int64_t num_cells, const int32_t *restrict cells, const double *restrict X,
                  const double *restrict u, const double *restrict v, const element_params *p,
                  double *restrict state, int64_t stride, double *restrict f,
                  double *restrict energy, double *restrict step)
{
  vec Xe[12], ue[12], ve[12], fe[12];
  double stored = 0.0, dissipated = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 4, &b, X, Xe);
    gather(cells, 4, &b, u, ue);
    gather(cells, 4, &b, v, ve);
    vec x[12], xm[12], du[12], g[4][3], dL[9], sigma[9], eps_p, T;
    for (int i = 0; i < 12; ++i)
    {
      du[i] = p->dt * ve[i];
      x[i] = Xe[i] + ue[i];
      xm[i] = x[i] - 0.5 * du[i];
    }
    const vec mid_volume = tet4_geometry(xm, g);
    tet4_gradient(du, g, dL);
    load_point(state, stride, &b, 0, sigma, &eps_p, &T);
    point_step done;
    const vec dissipation = plastic_update(p, sigma, &eps_p, &T, dL, &done);
    store_point(state, stride, &b, 0, sigma, eps_p, T);
    const vec damage = accumulate_damage(p, state, stride, &b, p->damage_slot, &done, T);
    vec det;
    const vec volume = tet4_geometry_signed(x, g, &det);
    tet4_nodal_forces(volume, sigma, g, fe);
    const vec elastic = volume * elastic_energy_density(p, sigma);
    const vec plastic = mid_volume * dissipation;
    dissipated += lane_sum(plastic, b.nb);
    const ivec inverted = det <= 0.0;
    vec dte = VZERO + INFINITY;
    if (p->estimate)
    {
      const vec speed = p->wave_speed * vsqrt(volume / cell_values(p->volume0, &b));
      dte = p->calibration * characteristic_length(4, x, volume) / speed;
    }
    const ivec failed = erode_plastic(p, &b, damage, inverted, dte, elastic, plastic, NULL,
                                      du, fe, 4, energy, step);
    stored += lane_sum(vselect(failed, VZERO, elastic), b.nb);
    add_batch(p, cells, 4, &b, inverted, failed, dte, x, NULL, fe, f, step);
  }
  energy[0] += stored;
  energy[2] += dissipated;
}

/* One function per law: f += f_int(u) on the cells (N), energy[0] += stored energy (J);
 * the element steps and inverted cells in step (step.h). */
#define TET4(MODEL, model_name)                                                                 \
  void tet4_##model_name(int64_t n, const int32_t *cells, const double *X, const double *u,    \
                         const element_params *p, double *f, double *energy, double *step)     \
  {                                                                                             \
    tet4_force(MODEL, n, cells, X, u, p, f, energy, step);                                      \
  }
TET4(LINEAR_ELASTIC, linear_elastic)
TET4(SAINT_VENANT_KIRCHHOFF, saint_venant_kirchhoff)
TET4(NEO_HOOKEAN, neo_hookean)

/* The volume (m^3) and characteristic length (m, step.h) of each tetrahedron at x. */
void tet4_cell_sizes(int64_t num_cells, const int32_t *cells, const double *x, double *volume,
                     double *length)
{
  vec xe[12], g[4][3];
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(NULL, k0, num_cells);
    gather(cells, 4, &b, x, xe);
    const vec v = tet4_geometry(xe, g);
    const vec l = characteristic_length(4, xe, v);
    for (int k = 0; k < b.nb; ++k)
    {
      volume[k0 + k] = v[k];
      length[k0 + k] = l[k];
    }
  }
}
