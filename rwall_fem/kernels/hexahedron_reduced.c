/* Internal force of the one-point Q1 hexahedron with hourglass control.
 *
 * Notation (docs/theory.md, "One-point hexahedra"): node I of DOLFINx's
 * numbering has reference signs Lambda_I = (xi_I, eta_I, zeta_I) and hourglass
 * signs h_I = (eta_I zeta_I, xi_I zeta_I, xi_I eta_I, xi_I eta_I zeta_I).  From
 * the nodal coordinates,
 *     e_k = 1/8 sum_I Lambda_kI x_I   (the columns of the Jacobian at the centre),
 *     c_a = 1/8 sum_I h_aI x_I        (the coordinates' hourglass parts),
 * the exact volume is the cubic
 *     V = 8 [e0.(e1 x e2) + (e0.(c2 x c1) + c1.(c0 x e2) + c2.(e1 x c0)) / 3]
 * and its gradient dV/dx_I gives the uniform (mean) gradient of Flanagan and
 * Belytschko (1981), b_I = (1/V) int grad N_I dV = (dV/dx_I) / V.  The centre
 * point integrates f_I = |V| T(grad u) b_I, with grad u = sum_I u_I (x) b_I
 * (a linear field gives exactly zero force on interior nodes: the patch test).
 *
 * Hourglass modes: q_a = sum_I gamma_aI u_I with gamma_aI = h_aI / 8 - c_a . b_I,
 * orthogonal to every linear field.  The hourglass generalized forces Q_a act
 * back through f_I += sum_a gamma_aI Q_a:
 * - "physical" (assumed strain, Belytschko and Bindeman 1993, the kind of
 *   Radioss's HEPH): the trilinear field's strain at xi is eps_0 plus
 *   xi A_xi + eta A_eta + zeta A_zeta + eta zeta A_etazeta + ..., with
 *   A_xi = sym(q1 (x) g2 + q2 (x) g1), ..., A_etazeta = sym(q3 (x) g0), ... and
 *   g_k = grad xi_k at the centre (rows of J0^-1).  Integrating its energy over
 *   the cube (means 1/3 and 1/9 of the squared monomials) gives
 *   Q0 = |V|/3 (S_zeta g1 + S_eta g2), Q1 = |V|/3 (S_zeta g0 + S_xi g2),
 *   Q2 = |V|/3 (S_eta g0 + S_xi g1), Q3 = |V|/9 (S_etazeta g0 + S_xizeta g1 + S_xieta g2)
 *   with S = lambda tr(A) I + 2 mu A: on a parallelepiped exactly the fully
 *   integrated Q1 element for linear elasticity; stored energy 1/2 sum Q_a . q_a.
 * - "stiffness" (Flanagan-Belytschko): Q_a = kappa q_a,
 *   kappa = (lambda + 2 mu) |V| (sum_I b_I . b_I) / 3; stored energy 1/2 kappa |q|^2.
 * - "viscous" (Flanagan-Belytschko with LS-DYNA's scaling of its type 1-3 forms):
 *   Q_a = 16 rho c |V|^(2/3) qdot_a, qdot_a = sum_I gamma_aI v_I; dissipates
 *   dt sum_a Q_a . qdot_a per step.
 * each times the hourglass coefficient.  energy[0] += stored elastic energy,
 * energy[1] += hourglass energy (stored) or its dissipation in this step.
 */
#include "failure.h"
#include "materials.h"

enum
{
  HOURGLASS_NONE = 0,
  HOURGLASS_PHYSICAL = 1,
  HOURGLASS_STIFFNESS = 2,
  HOURGLASS_VISCOUS = 3
};

static const double LAMBDA_SIGN[3][8] = {{-1, 1, -1, 1, -1, 1, -1, 1},
                                         {-1, -1, 1, 1, -1, -1, 1, 1},
                                         {-1, -1, -1, -1, 1, 1, 1, 1}};
static const double H_SIGN[4][8] = {{1, 1, -1, -1, -1, -1, 1, 1},
                                    {1, -1, 1, -1, -1, 1, -1, 1},
                                    {1, -1, -1, 1, 1, -1, -1, 1},
                                    {-1, 1, 1, -1, 1, -1, -1, 1}};

/* (lambda tr(A) I + 2 mu A) y with A = sym(a (x) g + b (x) h): an hourglass stress applied to y. */
INLINE void hourglass_stress_times(const vec a[3], const vec g[3], const vec b[3], const vec h[3],
                                   const vec y[3], double lambda, double mu, vec out[3])
{
  const vec tr = dot3(a, g) + dot3(b, h);
  const vec gy = dot3(g, y), ay = dot3(a, y), hy = dot3(h, y), by = dot3(b, y);
  for (int i = 0; i < 3; ++i)
    out[i] = lambda * tr * y[i] + mu * (a[i] * gy + g[i] * ay + b[i] * hy + h[i] * by);
}

/* What the one-point hexahedron needs of its nodal coordinates. */
typedef struct
{
  vec V;         /* signed volume, m^3 (positive for the orientation of elasto-plastic cells) */
  vec c[4][3];   /* hourglass parts of the coordinates, m */
  vec E[3][3];   /* e1 x e2, e2 x e0, e0 x e1: det0 times the rows of J0^-1, m^2 */
  vec det0;      /* det J0, m^3 / 8 */
  vec volume;    /* |V|, m^3 */
  vec b[8][3];   /* uniform gradient, 1/m */
} hex8r_geometry_t;

INLINE void hex8r_geometry(const vec *restrict x, hex8r_geometry_t *geo)
{
  vec e[3][3], (*c)[3] = geo->c, (*E)[3] = geo->E;
  for (int i = 0; i < 3; ++i)
  {
    for (int m = 0; m < 3; ++m)
    {
      e[m][i] = VZERO;
      for (int I = 0; I < 8; ++I)
        e[m][i] += (0.125 * LAMBDA_SIGN[m][I]) * x[3 * I + i];
    }
    for (int a = 0; a < 4; ++a)
    {
      c[a][i] = VZERO;
      for (int I = 0; I < 8; ++I)
        c[a][i] += (0.125 * H_SIGN[a][I]) * x[3 * I + i];
    }
  }
  /* dV/dx_I = sum_m Lambda_mI D_m + sum_a<3 h_aI M_a */
  vec D[3][3], M[3][3], t1[3], t2[3];
  cross(e[1], e[2], E[0]);
  cross(e[2], e[0], E[1]);
  cross(e[0], e[1], E[2]);
  cross(c[2], c[1], t1);
  for (int i = 0; i < 3; ++i)
    D[0][i] = E[0][i] + (1.0 / 3.0) * t1[i];
  cross(c[0], c[2], t1);
  for (int i = 0; i < 3; ++i)
    D[1][i] = E[1][i] + (1.0 / 3.0) * t1[i];
  cross(c[1], c[0], t1);
  for (int i = 0; i < 3; ++i)
    D[2][i] = E[2][i] + (1.0 / 3.0) * t1[i];
  cross(e[2], c[1], t1);
  cross(c[2], e[1], t2);
  for (int i = 0; i < 3; ++i)
    M[0][i] = (1.0 / 3.0) * (t1[i] + t2[i]);
  cross(e[0], c[2], t1);
  cross(c[0], e[2], t2);
  for (int i = 0; i < 3; ++i)
    M[1][i] = (1.0 / 3.0) * (t1[i] + t2[i]);
  cross(c[1], e[0], t1);
  cross(e[1], c[0], t2);
  for (int i = 0; i < 3; ++i)
    M[2][i] = (1.0 / 3.0) * (t1[i] + t2[i]);

  geo->det0 = dot3(e[0], E[0]);
  cross(c[2], c[1], t1);
  vec V = dot3(e[0], t1);
  cross(c[0], e[2], t1);
  V += dot3(c[1], t1);
  cross(e[1], c[0], t1);
  V += dot3(c[2], t1);
  V = 8.0 * geo->det0 + (8.0 / 3.0) * V;
  geo->V = V;
  geo->volume = vabs(V);
  const vec inv_V = 1.0 / V;
  for (int I = 0; I < 8; ++I)
    for (int j = 0; j < 3; ++j)
      geo->b[I][j] = (LAMBDA_SIGN[0][I] * D[0][j] + LAMBDA_SIGN[1][I] * D[1][j]
                      + LAMBDA_SIGN[2][I] * D[2][j] + H_SIGN[0][I] * M[0][j]
                      + H_SIGN[1][I] * M[1][j] + H_SIGN[2][I] * M[2][j]) * inv_V;
}

/* L = sum_I w_I (x) b_I for nodal vectors w[3 I + i]. */
INLINE void hex8r_gradient(const vec *restrict w, const hex8r_geometry_t *geo, vec L[9])
{
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      L[3 * i + j] = VZERO;
      for (int I = 0; I < 8; ++I)
        L[3 * i + j] += w[3 * I + i] * geo->b[I][j];
    }
}

/* f_I = |V| T b_I */
INLINE void hex8r_nodal_forces(const hex8r_geometry_t *geo, const vec T[9], vec *restrict f)
{
  for (int I = 0; I < 8; ++I)
    for (int i = 0; i < 3; ++i)
      f[3 * I + i] = geo->volume * (T[3 * i] * geo->b[I][0] + T[3 * i + 1] * geo->b[I][1]
                                    + T[3 * i + 2] * geo->b[I][2]);
}

/* gamma_aI = h_aI / 8 - c_a . b_I, and the hourglass amplitudes q_a = sum_I gamma_aI w_I. */
INLINE void hourglass_modes(const hex8r_geometry_t *geo, const vec *restrict w, vec gamma[4][8],
                            vec q[4][3])
{
  for (int a = 0; a < 4; ++a)
  {
    for (int I = 0; I < 8; ++I)
      gamma[a][I] = 0.125 * H_SIGN[a][I] - dot3(geo->c[a], geo->b[I]);
    for (int i = 0; i < 3; ++i)
    {
      q[a][i] = VZERO;
      for (int I = 0; I < 8; ++I)
        q[a][i] += gamma[a][I] * w[3 * I + i];
    }
  }
}

/* The generalized hourglass forces Q_a of amplitudes q_a: linear in q (see the header).
 * ``lambda`` is the first Lame parameter of the physical form's hourglass stresses: the
 * material's for elastic bodies (full integration on parallelepipeds), 0 for plastic flow,
 * where a volumetric hourglass stiffness would lock the nearly incompressible flow. */
INLINE void hourglass_forces(int hourglass, const hex8r_geometry_t *geo, const vec q[4][3],
                             const element_params *p, double lambda, vec Q[4][3])
{
  const double scale = p->hourglass_coefficient;
  if (hourglass == HOURGLASS_PHYSICAL)
  {
    const double mu = p->mu;
    const vec zero[3] = {VZERO, VZERO, VZERO};
    vec g[3][3], s1[3], s2[3], s3[3];
    const vec inv_det0 = 1.0 / geo->det0;
    for (int m = 0; m < 3; ++m)
      for (int i = 0; i < 3; ++i)
        g[m][i] = geo->E[m][i] * inv_det0;
    const vec third = (scale / 3.0) * geo->volume, ninth = (scale / 9.0) * geo->volume;
    /* Q0 = |V|/3 (S_zeta g1 + S_eta g2); A_zeta = sym(q0 g1 + q1 g0), A_eta = sym(q0 g2 + q2 g0) */
    hourglass_stress_times(q[0], g[1], q[1], g[0], g[1], lambda, mu, s1);
    hourglass_stress_times(q[0], g[2], q[2], g[0], g[2], lambda, mu, s2);
    for (int i = 0; i < 3; ++i)
      Q[0][i] = third * (s1[i] + s2[i]);
    /* Q1 = |V|/3 (S_zeta g0 + S_xi g2); A_xi = sym(q1 g2 + q2 g1) */
    hourglass_stress_times(q[0], g[1], q[1], g[0], g[0], lambda, mu, s1);
    hourglass_stress_times(q[1], g[2], q[2], g[1], g[2], lambda, mu, s2);
    for (int i = 0; i < 3; ++i)
      Q[1][i] = third * (s1[i] + s2[i]);
    /* Q2 = |V|/3 (S_eta g0 + S_xi g1) */
    hourglass_stress_times(q[0], g[2], q[2], g[0], g[0], lambda, mu, s1);
    hourglass_stress_times(q[1], g[2], q[2], g[1], g[1], lambda, mu, s2);
    for (int i = 0; i < 3; ++i)
      Q[2][i] = third * (s1[i] + s2[i]);
    /* Q3 = |V|/9 (S_etazeta g0 + S_xizeta g1 + S_xieta g2), A_.. = sym(q3 g_k) */
    hourglass_stress_times(q[3], g[0], zero, zero, g[0], lambda, mu, s1);
    hourglass_stress_times(q[3], g[1], zero, zero, g[1], lambda, mu, s2);
    hourglass_stress_times(q[3], g[2], zero, zero, g[2], lambda, mu, s3);
    for (int i = 0; i < 3; ++i)
      Q[3][i] = ninth * (s1[i] + s2[i] + s3[i]);
    return;
  }
  vec kappa;
  if (hourglass == HOURGLASS_STIFFNESS)
  {
    vec bb = VZERO;
    for (int I = 0; I < 8; ++I)
      bb += dot3(geo->b[I], geo->b[I]);
    kappa = (scale * (p->lmbda + 2.0 * p->mu) / 3.0) * geo->volume * bb;
  }
  else
    kappa = (scale * 16.0 * p->density * p->wave_speed) * vcbrt(geo->volume * geo->volume);
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      Q[a][i] = kappa * q[a][i];
}

/* f_I += sum_a gamma_aI Q_a */
INLINE void hourglass_nodal_forces(const vec gamma[4][8], const vec Q[4][3], vec *restrict f)
{
  for (int I = 0; I < 8; ++I)
    for (int i = 0; i < 3; ++i)
      f[3 * I + i] += gamma[0][I] * Q[0][i] + gamma[1][I] * Q[1][i] + gamma[2][I] * Q[2][i]
                      + gamma[3][I] * Q[3][i];
}

/* The nodal forces f[3 I + i] of a batch; *stored = elastic energy, *hourglass_energy =
 * hourglass energy (stored) or dissipation in this step (viscous), per cell; *jacobian =
 * det(I + grad u) at the centre, *modulus = rho_0 c^2 there (Pa, when p->estimate),
 * *volume = the volume at rest (m^3). */
INLINE void hex8r_cell(int model, int hourglass, const vec *restrict x, const vec *restrict u,
                       const vec *restrict v, vec *restrict f, vec *restrict stored,
                       vec *restrict hourglass_energy, const element_params *p,
                       vec *jacobian, vec *modulus, vec *volume)
{
  hex8r_geometry_t geo;
  hex8r_geometry(x, &geo);
  vec L[9], T[9];
  hex8r_gradient(u, &geo, L);
  *stored = geo.volume * stress(model, L, p->lmbda, p->mu, T);
  hex8r_nodal_forces(&geo, T, f);
  *jacobian = volume_ratio(L);
  *volume = geo.volume;
  if (p->estimate)
    *modulus = wave_modulus(model, L, p->lmbda, p->mu);
  *hourglass_energy = VZERO;
  if (hourglass == HOURGLASS_NONE)
    return;
  vec gamma[4][8], q[4][3], Q[4][3];
  hourglass_modes(&geo, hourglass == HOURGLASS_VISCOUS ? v : u, gamma, q);
  hourglass_forces(hourglass, &geo, q, p, p->lmbda, Q);
  vec work = VZERO;
  for (int a = 0; a < 4; ++a)
    work += dot3(Q[a], q[a]);
  *hourglass_energy = hourglass == HOURGLASS_VISCOUS ? p->dt * work : 0.5 * work;
  hourglass_nodal_forces(gamma, Q, f);
}

/* Total Lagrangian one-point hexahedra: the stable step of a cell is L_0 / c with its
 * length at rest and the wave speed of the law at its strain, and with the viscous form
 * at most that of its damped hourglass modes (step.h); erosion as failure.h says (the
 * viscous form's dissipation is tracked per cell in p->cell_work for it). */
INLINE void hex8r_force(int model, int hourglass, int64_t num_cells,
                        const int32_t *restrict cells, const double *restrict X,
                        const double *restrict u, const double *restrict v,
                        const element_params *p, double *restrict f, double *restrict energy,
                        double *restrict step)
{
  vec x[24], ue[24], ve[24], fe[24], stored, hourglass_energy, jacobian, modulus, volume;
  double total = 0.0, hourglass_total = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 8, &b, X, x);
    gather(cells, 8, &b, u, ue);
    if (hourglass == HOURGLASS_VISCOUS)
      gather(cells, 8, &b, v, ve);
    hex8r_cell(model, hourglass, x, ue, ve, fe, &stored, &hourglass_energy, p, &jacobian,
               &modulus, &volume);
    vec xc[24];
    for (int i = 0; i < 24; ++i)
      xc[i] = x[i] + ue[i];
    const ivec inverted = (jacobian <= 0.0) | hex8_corners_inverted(xc);
    vec dte = VZERO + INFINITY;
    if (p->estimate)
    {
      dte = p->calibration * cell_values(p->length0, &b) * vsqrt(p->density / modulus);
      if (hourglass == HOURGLASS_VISCOUS)
        dte = vmin(dte, viscous_hourglass_step(p, volume, volume));
    }
    const ivec failed = failed_lanes(p, VZERO, inverted, dte, stored + hourglass_energy);
    /* the viscous form's dissipation accumulates; the other forms' energy is stored */
    if (hourglass == HOURGLASS_VISCOUS)
      track_work(p, &b, 1, hourglass_energy);
    if (any_lane(failed))
    {
      vec du[24];
      increments(p, cells, 8, &b, du);
      const vec dissipated = hourglass == HOURGLASS_VISCOUS ? work_so_far(p, &b, 1) : VZERO;
      const vec held = hourglass == HOURGLASS_VISCOUS ? dissipated : hourglass_energy;
      erode(p, failed, &b, energy_left(stored + held, du, fe, 8), VZERO, dissipated, fe, 8,
            energy, step);
    }
    total += lane_sum(vselect(failed, VZERO, stored), b.nb);
    /* the viscous form's work of this step counts (erode took the cell's total back out) */
    const vec kept = vselect(failed, VZERO, hourglass_energy);
    hourglass_total += lane_sum(hourglass == HOURGLASS_VISCOUS ? hourglass_energy : kept, b.nb);
    add_batch(p, cells, 8, &b, inverted, failed, dte, x, ue, fe, f, step);
  }
  energy[0] += total;
  energy[1] += hourglass_total;
}

/* Elasto-plastic one-point hexahedra (updated Lagrangian, plasticity.h): the increment
 * du = dt v (dt = 0 at the first step) has its gradient taken with the uniform gradient of
 * the mid-step configuration; the force is that of the updated stress in the current one,
 * x = X + u.  The hourglass forces are incremental, Q^n = R Q^{n-1} + dQ(dq) with the
 * element's rotation R and dq the hourglass amplitudes of du in the current configuration
 * (the viscous form: Q = Q(dq / dt)); the state keeps Q after the point's slots, then the
 * damage row of failure.h, which also says how cells fail and are eroded.
 * energy[0] += stored elastic energy (J), energy[1] += hourglass work of the step,
 * energy[2] += plastic dissipation of the step; a cell is inverted when its volume is not
 * positive, and its stable step is L / c in the current configuration, c from the elastic
 * moduli and the current density, with the viscous form at most that of its damped
 * hourglass modes (step.h). */
INLINE void hex8r_plastic(int hourglass, int64_t num_cells, const int32_t *restrict cells,
                          const double *restrict X, const double *restrict u,
                          const double *restrict v, const element_params *p,
                          double *restrict state, int64_t stride, double *restrict f,
                          double *restrict energy, double *restrict step)
{
  vec Xe[24], ue[24], ve[24], fe[24];
  double stored = 0.0, hourglass_work = 0.0, dissipated = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    gather(cells, 8, &b, X, Xe);
    gather(cells, 8, &b, u, ue);
    gather(cells, 8, &b, v, ve);
    vec x[24], xm[24], du[24], dL[9], sigma[9], eps_p, T;
    for (int i = 0; i < 24; ++i)
    {
      du[i] = p->dt * ve[i];
      x[i] = Xe[i] + ue[i];
      xm[i] = x[i] - 0.5 * du[i];
    }
    hex8r_geometry_t geo;
    hex8r_geometry(xm, &geo);
    const vec mid_volume = geo.volume;
    hex8r_gradient(du, &geo, dL);
    load_point(state, stride, &b, 0, sigma, &eps_p, &T);
    point_step done;
    const vec dissipation = plastic_update(p, sigma, &eps_p, &T, dL, &done);
    store_point(state, stride, &b, 0, sigma, eps_p, T);
    const vec damage = accumulate_damage(p, state, stride, &b, p->damage_slot, &done, T);
    hex8r_geometry(x, &geo);
    const ivec inverted = (geo.V <= 0.0) | hex8_corners_inverted(x);
    vec dte = VZERO + INFINITY;
    if (p->estimate)
    {
      const vec volume0 = cell_values(p->volume0, &b);
      const vec speed = p->wave_speed * vsqrt(geo.volume / volume0);
      dte = p->calibration * characteristic_length(8, x, geo.volume) / speed;
      if (hourglass == HOURGLASS_VISCOUS)
        dte = vmin(dte, viscous_hourglass_step(p, geo.volume, volume0));
    }
    hex8r_nodal_forces(&geo, sigma, fe);
    const vec elastic = geo.volume * elastic_energy_density(p, sigma);
    const vec plastic = mid_volume * dissipation;
    dissipated += lane_sum(plastic, b.nb);
    vec work = VZERO;
    if (hourglass != HOURGLASS_NONE)
    {
      vec gamma[4][8], dq[4][3], Q[4][3];
      hourglass_modes(&geo, du, gamma, dq);
      if (hourglass == HOURGLASS_VISCOUS)
      {
        const double rate = p->dt > 0.0 ? 1.0 / p->dt : 0.0;
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i)
            dq[a][i] *= rate;
        hourglass_forces(hourglass, &geo, dq, p, 0.0, Q);
        for (int a = 0; a < 4; ++a)
          work += p->dt * dot3(Q[a], dq[a]);
      }
      else
      {
        vec R[9], Q_old[4][3], dQ[4][3];
        rotation(dL, R);
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i)
            Q_old[a][i] = load_slot(state, stride, &b, POINT_SLOTS + 3 * a + i);
        hourglass_forces(hourglass, &geo, dq, p, 0.0, dQ);
        for (int a = 0; a < 4; ++a)
        {
          for (int i = 0; i < 3; ++i)
          {
            const vec rotated = R[3 * i] * Q_old[a][0] + R[3 * i + 1] * Q_old[a][1]
                                + R[3 * i + 2] * Q_old[a][2];
            Q[a][i] = rotated + dQ[a][i];
            work += (rotated + 0.5 * dQ[a][i]) * dq[a][i];
            store_slot(state, stride, &b, POINT_SLOTS + 3 * a + i, Q[a][i]);
          }
        }
      }
      hourglass_nodal_forces(gamma, Q, fe);
      hourglass_work += lane_sum(work, b.nb);
    }
    const ivec failed = erode_plastic(p, &b, damage, inverted, dte, elastic, plastic, &work,
                                      du, fe, 8, energy, step);
    stored += lane_sum(vselect(failed, VZERO, elastic), b.nb);
    add_batch(p, cells, 8, &b, inverted, failed, dte, x, NULL, fe, f, step);
  }
  energy[0] += stored;
  energy[1] += hourglass_work;
  energy[2] += dissipated;
}

/* One function per law and hourglass control: f += f_int(u) on the cells (N); energy[0] +=
 * stored elastic energy (J), energy[1] += hourglass energy or dissipation (J); the element
 * steps and inverted cells in step (step.h). v (m/s) is read by the viscous form only. */
#define HEX8R(MODEL, model_name, HOURGLASS, hourglass_name)                                    \
  void hex8r_##model_name##_##hourglass_name(int64_t n, const int32_t *cells, const double *X, \
                                             const double *u, const double *v,                 \
                                             const element_params *p, double *f,               \
                                             double *energy, double *step)                     \
  {                                                                                            \
    hex8r_force(MODEL, HOURGLASS, n, cells, X, u, v, p, f, energy, step);                      \
  }
#define HEX8R_ALL_HOURGLASS(MODEL, model_name)                                                 \
  HEX8R(MODEL, model_name, HOURGLASS_NONE, none)                                               \
  HEX8R(MODEL, model_name, HOURGLASS_PHYSICAL, physical)                                       \
  HEX8R(MODEL, model_name, HOURGLASS_STIFFNESS, stiffness)                                     \
  HEX8R(MODEL, model_name, HOURGLASS_VISCOUS, viscous)

HEX8R_ALL_HOURGLASS(LINEAR_ELASTIC, linear_elastic)
HEX8R_ALL_HOURGLASS(SAINT_VENANT_KIRCHHOFF, saint_venant_kirchhoff)
HEX8R_ALL_HOURGLASS(NEO_HOOKEAN, neo_hookean)

/* Elasto-plastic one-point hexahedra, one function per hourglass control (hex8r_plastic). */
#define HEX8R_PLASTIC(HOURGLASS, hourglass_name)                                                \
  void hex8r_plastic_##hourglass_name(int64_t n, const int32_t *cells, const double *X,        \
                                      const double *u, const double *v, const element_params *p, \
                                      double *state, int64_t stride, double *f, double *energy,  \
                                      double *step)                                              \
  {                                                                                             \
    hex8r_plastic(HOURGLASS, n, cells, X, u, v, p, state, stride, f, energy, step);             \
  }
HEX8R_PLASTIC(HOURGLASS_NONE, none)
HEX8R_PLASTIC(HOURGLASS_PHYSICAL, physical)
HEX8R_PLASTIC(HOURGLASS_STIFFNESS, stiffness)
HEX8R_PLASTIC(HOURGLASS_VISCOUS, viscous)

/* The volume (m^3) and characteristic length (m, step.h) of each hexahedron at x: what the
 * element step estimate of the kernels needs of the cells at rest. */
void hex8_cell_sizes(int64_t num_cells, const int32_t *cells, const double *x, double *volume,
                     double *length)
{
  vec xe[24];
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(NULL, k0, num_cells);
    gather(cells, 8, &b, x, xe);
    hex8r_geometry_t geo;
    hex8r_geometry(xe, &geo);
    const vec l = characteristic_length(8, xe, geo.volume);
    for (int k = 0; k < b.nb; ++k)
    {
      volume[k0 + k] = geo.volume[k];
      length[k0 + k] = l[k];
    }
  }
}
