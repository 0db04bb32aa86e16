/* Internal force of the Q1 (trilinear) hexahedron, full 2 x 2 x 2 Gauss integration.
 *
 * Reference cube [-1, 1]^3; node I of DOLFINx's numbering sits at
 * (xi_I, eta_I, zeta_I) = (2 (I & 1) - 1, 2 (I >> 1 & 1) - 1, 2 (I >> 2 & 1) - 1)
 * and N_I = (1 + xi_I xi)(1 + eta_I eta)(1 + zeta_I zeta) / 8.  At each of the
 * eight points (+-1/sqrt 3)^3 (weight 1): J = dx/dxi, grad N_I = J^-T dN_I/dxi,
 * f_I += |det J| T(grad u) grad N_I (materials.h).  This is the rule UFL uses
 * with quadrature degree 2 on hexahedra, which the tests compare against.
 */
#include "failure.h"
#include "materials.h"

static const double SIGN[8][3] = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {-1, 1, 1},  {1, 1, 1}};

/* Shape function gradients g[I] (1/m) at Gauss point q of the hexahedra at x[3 I + i];
 * returns det J (m^3 / 8, signed). */
INLINE vec hex8_point_geometry(const vec *restrict x, int q, vec g[8][3])
{
  const double a = 0.57735026918962576451; /* 1/sqrt(3) */
  double dN[8][3];
  for (int I = 0; I < 8; ++I)
  {
    const double s[3] = {1.0 + a * SIGN[I][0] * SIGN[q][0], 1.0 + a * SIGN[I][1] * SIGN[q][1],
                         1.0 + a * SIGN[I][2] * SIGN[q][2]};
    dN[I][0] = 0.125 * SIGN[I][0] * s[1] * s[2];
    dN[I][1] = 0.125 * SIGN[I][1] * s[0] * s[2];
    dN[I][2] = 0.125 * SIGN[I][2] * s[0] * s[1];
  }
  vec J[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      J[3 * i + j] = VZERO;
      for (int I = 0; I < 8; ++I)
        J[3 * i + j] += x[3 * I + i] * dN[I][j];
    }
  /* J^-1 = cof(J)^T / det J */
  vec inv[9];
  inv[0] = J[4] * J[8] - J[5] * J[7];
  inv[1] = J[2] * J[7] - J[1] * J[8];
  inv[2] = J[1] * J[5] - J[2] * J[4];
  inv[3] = J[5] * J[6] - J[3] * J[8];
  inv[4] = J[0] * J[8] - J[2] * J[6];
  inv[5] = J[2] * J[3] - J[0] * J[5];
  inv[6] = J[3] * J[7] - J[4] * J[6];
  inv[7] = J[1] * J[6] - J[0] * J[7];
  inv[8] = J[0] * J[4] - J[1] * J[3];
  const vec det = J[0] * inv[0] + J[1] * inv[3] + J[2] * inv[6], inv_det = 1.0 / det;
  for (int I = 0; I < 8; ++I)
    for (int j = 0; j < 3; ++j)
      g[I][j] = (dN[I][0] * inv[j] + dN[I][1] * inv[3 + j] + dN[I][2] * inv[6 + j]) * inv_det;
  return det;
}

/* L = sum_I w_I (x) g_I for nodal vectors w[3 I + i]. */
INLINE void hex8_gradient(const vec *restrict w, vec g[8][3], vec L[9])
{
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      L[3 * i + j] = VZERO;
      for (int I = 0; I < 8; ++I)
        L[3 * i + j] += w[3 * I + i] * g[I][j];
    }
}

/* The nodal forces f[3 I + i] of a batch; returns the stored energy of each cell, and in
 * *jacobian the smallest det(I + grad u) of its points, in *modulus their largest
 * rho_0 c^2 (Pa, when p->estimate). */
INLINE vec hex8_cell(int model, const vec *restrict x, const vec *restrict u, vec *restrict f,
                     const element_params *p, vec *jacobian, vec *modulus)
{
  vec energy = VZERO;
  *jacobian = VZERO + INFINITY;
  *modulus = VZERO;
  for (int I = 0; I < 24; ++I)
    f[I] = VZERO;
  for (int q = 0; q < 8; ++q)
  {
    vec g[8][3], L[9], T[9];
    const vec weight = vabs(hex8_point_geometry(x, q, g));
    hex8_gradient(u, g, L);
    energy += weight * stress(model, L, p->lmbda, p->mu, T);
    for (int I = 0; I < 8; ++I)
      for (int i = 0; i < 3; ++i)
        f[3 * I + i] += weight * (T[3 * i] * g[I][0] + T[3 * i + 1] * g[I][1]
                                  + T[3 * i + 2] * g[I][2]);
    *jacobian = vmin(*jacobian, volume_ratio(L));
    if (p->estimate)
      *modulus = vmax(*modulus, wave_modulus(model, L, p->lmbda, p->mu));
  }
  return energy;
}

/* Total Lagrangian hexahedra: the stable step of a cell is L_0 / c with its length at
 * rest and the largest wave speed of the law at its points (step.h); erosion as failure.h
 * says. */
INLINE void hex8_force(int model, int64_t num_cells, const int32_t *restrict cells,
                       const double *restrict X, const double *restrict u,
                       const element_params *p, double *restrict f, double *restrict energy,
                       double *restrict step)
{
  vec x[24], ue[24], fe[24], jacobian, modulus;
  double total = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 8, &b, X, x);
    gather(cells, 8, &b, u, ue);
    const vec w = hex8_cell(model, x, ue, fe, p, &jacobian, &modulus);
    const ivec inverted = jacobian <= 0.0;
    vec dte = VZERO + INFINITY;
    if (p->estimate)
      dte = p->calibration * cell_values(p->length0, &b) * vsqrt(p->density / modulus);
    const ivec failed = failed_lanes(p, VZERO, inverted, dte, w);
    if (any_lane(failed))
    {
      vec du[24];
      increments(p, cells, 8, &b, du);
      erode(p, failed, &b, energy_left(w, du, fe, 8), VZERO, VZERO, fe, 8, energy, step);
    }
    total += lane_sum(vselect(failed, VZERO, w), b.nb);
    add_batch(p, cells, 8, &b, inverted, failed, dte, x, ue, fe, f, step);
  }
  energy[0] += total;
}

/* Elasto-plastic Q1 hexahedra, 2x2x2 points with mean dilatation (B-bar: every point
 * takes the element's mean volumetric increment, and the pressure acts through the mean
 * gradient), updated Lagrangian as tet4_plastic; the state holds POINT_SLOTS slots per
 * point, and the damage rows of failure.h (a cell fails when one of its points does).
 * energy[0] += stored elastic energy (J), energy[2] += plastic dissipation; a cell is
 * inverted when det J <= 0 at a point, and its stable step is L / c in the current
 * configuration (step.h). */
void hex8_plastic(int64_t num_cells, const int32_t *restrict cells, const double *restrict X,
                  const double *restrict u, const double *restrict v, const element_params *p,
                  double *restrict state, int64_t stride, double *restrict f,
                  double *restrict energy, double *restrict step)
{
  vec Xe[24], ue[24], ve[24], fe[24];
  double stored = 0.0, dissipated = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 8, &b, X, Xe);
    gather(cells, 8, &b, u, ue);
    gather(cells, 8, &b, v, ve);
    vec x[24], xm[24], du[24], smallest = VZERO + INFINITY;
    for (int i = 0; i < 24; ++i)
    {
      du[i] = p->dt * ve[i];
      x[i] = Xe[i] + ue[i];
      xm[i] = x[i] - 0.5 * du[i];
    }
    /* mid-step gradients of every point, and the mean volumetric increment */
    vec gm[8][8][3], wm[8], trace = VZERO, volume = VZERO;
    for (int q = 0; q < 8; ++q)
    {
      wm[q] = vabs(hex8_point_geometry(xm, q, gm[q]));
      vec tr = VZERO;
      for (int I = 0; I < 8; ++I)
        tr += du[3 * I] * gm[q][I][0] + du[3 * I + 1] * gm[q][I][1] + du[3 * I + 2] * gm[q][I][2];
      trace += wm[q] * tr;
      volume += wm[q];
    }
    const vec mean_trace = trace / volume;
    vec dissipation = VZERO, sigma[8][9], damage = VZERO;
    for (int q = 0; q < 8; ++q)
    {
      vec dL[9], eps_p, T;
      hex8_gradient(du, gm[q], dL);
      const vec shift = (1.0 / 3.0) * (mean_trace - (dL[0] + dL[4] + dL[8]));
      dL[0] += shift, dL[4] += shift, dL[8] += shift;
      load_point(state, stride, &b, POINT_SLOTS * q, sigma[q], &eps_p, &T);
      point_step done;
      dissipation += wm[q] * plastic_update(p, sigma[q], &eps_p, &T, dL, &done);
      store_point(state, stride, &b, POINT_SLOTS * q, sigma[q], eps_p, T);
      const int slot = p->damage_slot + q;
      damage = vmax(damage, accumulate_damage(p, state, stride, &b, slot, &done, T));
    }
    /* f_I = sum_q w_q s_q g_Iq + (sum_q w_q p_q) (sum_q w_q g_Iq) / sum_q w_q */
    vec G[24], pressure = VZERO, elastic = VZERO;
    volume = VZERO;
    for (int I = 0; I < 24; ++I)
      fe[I] = G[I] = VZERO;
    for (int q = 0; q < 8; ++q)
    {
      vec g[8][3];
      const vec det = hex8_point_geometry(x, q, g), w = vabs(det);
      smallest = vmin(smallest, det);
      const vec pq = (1.0 / 3.0) * (sigma[q][0] + sigma[q][4] + sigma[q][8]);
      vec s[9];
      for (int i = 0; i < 9; ++i)
        s[i] = i % 4 == 0 ? sigma[q][i] - pq : sigma[q][i];
      for (int I = 0; I < 8; ++I)
        for (int i = 0; i < 3; ++i)
        {
          fe[3 * I + i] += w * (s[3 * i] * g[I][0] + s[3 * i + 1] * g[I][1] + s[3 * i + 2] * g[I][2]);
          G[3 * I + i] += w * g[I][i];
        }
      pressure += w * pq;
      volume += w;
      elastic += w * elastic_energy_density(p, sigma[q]);
    }
    const vec mean_pressure = pressure / volume;
    for (int I = 0; I < 24; ++I)
      fe[I] += mean_pressure * G[I];
    dissipated += lane_sum(dissipation, b.nb);
    const ivec inverted = smallest <= 0.0;
    vec dte = VZERO + INFINITY;
    if (p->estimate)
    {
      const vec speed = p->wave_speed * vsqrt(volume / cell_values(p->volume0, &b));
      dte = p->calibration * characteristic_length(8, x, volume) / speed;
    }
    const ivec failed = erode_plastic(p, &b, damage, inverted, dte, elastic, dissipation, NULL,
                                      du, fe, 8, energy, step);
    stored += lane_sum(vselect(failed, VZERO, elastic), b.nb);
    add_batch(p, cells, 8, &b, inverted, failed, dte, x, NULL, fe, f, step);
  }
  energy[0] += stored;
  energy[2] += dissipated;
}

/* One function per law: f += f_int(u) on the cells (N), energy[0] += stored energy (J);
 * the element steps and inverted cells in step (step.h). */
#define HEX8(MODEL, model_name)                                                                 \
  void hex8_##model_name(int64_t n, const int32_t *cells, const double *X, const double *u,    \
                         const element_params *p, double *f, double *energy, double *step)     \
  {                                                                                             \
    hex8_force(MODEL, n, cells, X, u, p, f, energy, step);                                      \
  }
HEX8(LINEAR_ELASTIC, linear_elastic)
HEX8(SAINT_VENANT_KIRCHHOFF, saint_venant_kirchhoff)
HEX8(NEO_HOOKEAN, neo_hookean)
