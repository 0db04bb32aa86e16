/* What the shell kernels share: their constants, the plane-stress J2 return and the
 * through-thickness rule (docs/theory.md, "Shell elements").
 *
 * Plane stress (sigma_zz = 0) in the cell's local frame; in-plane stresses and strains are
 * (xx, yy, xy) with the engineering shear strain gamma_xy = 2 eps_xy.  Hooke's law is
 * sigma = C eps, C = E / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]].
 *
 * The J2 return is exact for plane stress (Simo and Taylor 1985; Simo and Hughes,
 * Computational Inelasticity, section 3.4): with p = sxx + syy, d = syy - sxx and the
 * trial stress of the elastic predictor, the stress after a plastic multiplier g is
 *     p(g) = p_tr / (1 + k1 g),  d(g) = d_tr / (1 + 2 G g),  sxy(g) = sxy_tr / (1 + 2 G g),
 * k1 = E / (3 (1 - nu)), G = E / (2 (1 + nu)); its von Mises stress is
 *     q(g)^2 = p(g)^2 / 4 + 3 d(g)^2 / 4 + 3 sxy(g)^2
 * and the equivalent plastic strain grows by (2/3) g q(g).  g solves
 *     q(g) = sigma_y(eps_p + (2/3) g q(g)),
 * by Newton's method on sigma_y / q - 1 kept inside the bracket [0, (q_tr / sigma_y0 - 1) / k1]
 * (q(g) <= q_tr / (1 + k1 g) since k1 <= 2 G for nu <= 1/2; plane_stress_returns says how,
 * for all the points of a cell at once).  The normal stress through
 * the thickness is zero at every step by construction, and the plastic flow of the 3-D J2
 * law with sigma_zz = 0 is reproduced exactly (the thickness strain follows from it).
 * The flow stress is capped at p->max_flow_stress (Radioss LAW2's SIG_max0; plasticity.h).
 */
#ifndef RWALL_SHELL_H
#define RWALL_SHELL_H

#include "failure.h"

#define SHELL_MAX_POINTS 10
#define SHELL_POINT_SLOTS 5 /* sxx, syy, sxy (Pa), eps_p, temperature (K) */

/* The shell's constants of one kernel call (beside the material's element_params). */
typedef struct
{
  const double *thickness; /* per cell, m */
  int points;              /* N: integration points through the thickness (plastic kernels) */
  double zeta[SHELL_MAX_POINTS];   /* their heights over t, bottom to top (scaled: see below) */
  double weight[SHELL_MAX_POINTS]; /* their weights, summing to 1 */
  double young, poisson;   /* E (Pa), nu */
  double shear_factor;     /* of the transverse shear, 5/6 */
  double bar_speed;        /* sqrt(E / rho), m/s (Radioss's shell sound speed) */
  double hm, hf, hr;       /* viscous hourglass coefficients: membrane, out-of-plane, rotation */
  double fail_fraction;    /* a cell fails when this share of its points has failed */
  int warping;             /* 1: project out the rigid motion (warped cells), 0: plain BT */
  int omit_energy;         /* 1: skip the stored-energy sum (0 by default) */
  double hk;               /* elastic hourglass stiffness coefficient (0: viscous only) */
  int hourglass_slot;      /* the state's first row of the 5 elastic hourglass forces */
  double kd;               /* drilling stiffness coefficient (quadrilaterals; 0: none) */
  int drill_slot;          /* the state's first row of the 4 nodal drilling moments */
  double *new_thickness;   /* Radioss's Ithick = 1: the thicknesses to update (the array
                              `thickness` points to); NULL: constant */
  int qeph_step;           /* quadrilaterals, 1: QEPH's characteristic length (Ishell 24) */
  double qeph_dn;          /* its numerical damping dn: the length times sqrt(1 + dn^2) - dn */
  int qeph_hourglass;      /* quadrilaterals with hk > 0, elasto-plastic: QEPH's yielding
                              hourglass forces (Ishell 24; shell_quad.c, qeph_hourglass_yield) */
  int qeph_physical;       /* quadrilaterals, 1: QEPH's physical hourglass stiffness, 12 state
                              rows from hourglass_slot (shell_quad.c, quad_hourglass_qeph) */
} shell_params;

/* The motion of a batch's cells of npe nodes over the step dt (s): their nodes' initial
 * positions Xe, displacements ue (m), velocities ve (m/s) and angular velocities we (rad/s)
 * gathered (3 npe each), the positions x = X + u at the step's end and xm = x - dt/2 v at
 * mid-step (m), the increments du = (dt v, dt w) (6 npe: translations, then rotations), and
 * the cells' forces and moments fe (6 npe) zeroed. */
INLINE void shell_motion(const int32_t *restrict cells, int npe, const batch_t *b, double dt,
                         const double *X, const double *u, const double *v, const double *w,
                         vec *restrict Xe, vec *restrict ue, vec *restrict ve,
                         vec *restrict we, vec *restrict x, vec *restrict xm,
                         vec *restrict du, vec *restrict fe)
{
  gather(cells, npe, b, X, Xe);
  gather(cells, npe, b, u, ue);
  gather(cells, npe, b, v, ve);
  gather(cells, npe, b, w, we);
  const int n = 3 * npe;
  for (int i = 0; i < n; ++i)
  {
    x[i] = Xe[i] + ue[i];
    xm[i] = x[i] - (0.5 * dt) * ve[i];
    du[i] = dt * ve[i];
    du[n + i] = dt * we[i];
  }
  for (int i = 0; i < 2 * n; ++i)
    fe[i] = VZERO;
}

/* Plane-stress Hooke: (sxx, syy, sxy) += C (dxx, dyy, gxy) times `scale`. */
INLINE void hooke_add(const shell_params *s, vec scale, const vec de[3], vec out[3])
{
  const double E = s->young, nu = s->poisson, c = E / (1.0 - nu * nu), G = 0.5 * E / (1.0 + nu);
  out[0] += scale * (c * (de[0] + nu * de[1]));
  out[1] += scale * (c * (de[1] + nu * de[0]));
  out[2] += scale * (G * de[2]);
}

/* sigma . C^-1 sigma (J/m^3 times 2) of a plane stress. */
INLINE vec compliance_product(const shell_params *s, vec sxx, vec syy, vec sxy)
{
  const double E = s->young, nu = s->poisson;
  return (1.0 / E) * (sxx * sxx + syy * syy - (2.0 * nu) * sxx * syy
                      + (2.0 * (1.0 + nu)) * sxy * sxy);
}

/* The factor of the flow stress that does not depend on the plastic strain: Johnson-Cook's
 * rate and temperature factors (plasticity.h), 1 for the other laws; constant over a return. */
INLINE vec flow_factor(const element_params *p, vec rate, vec T)
{
  if (p->hardening != JOHNSON_COOK)
    return VZERO + 1.0;
  vec factor = 1.0 + p->rate_coefficient
                         * vlog(vmax(rate * (1.0 / p->reference_rate), VZERO + 1.0));
  if (p->thermal)
  {
    const vec star = vmin(vmax((T - p->room_temperature)
                                   * (1.0 / (p->melting_temperature - p->room_temperature)),
                               VZERO),
                          VZERO + 1.0);
    factor *= 1.0 - vpow(star, p->thermal_exponent);
  }
  return factor;
}

/* The flow stress (Pa) of plasticity.h at plastic strain e: the law capped at p->max_flow_stress
 * times `factor` (flow_factor; cap_flow_stress), and its slope (0 where the cap holds).
 * The power laws' e^n is taken as exp(n log e) on all lanes at once (batch.h), and its slope
 * as n e^n / e. */
INLINE vec capped_flow_stress(const element_params *p, vec e, vec factor,
                              vec *slope)
{
  vec y;
  if (p->hardening == HARDENING_POWER || p->hardening == JOHNSON_COOK)
  {
    const double B = p->hardening_coefficient, n = p->hardening_exponent;
    const ivec positive = e > 0.0;
    const vec safe = vselect(positive, e, VZERO + 1.0);
    const vec power = n == 0.0 ? VZERO + 1.0 : vselect(positive, vexp(n * vlog(safe)), VZERO);
    y = p->yield_stress + B * power;
    /* at e = 0 the slope of n < 1 is infinite: the Newton steps stay in their bracket */
    *slope = n == 0.0 ? VZERO : vselect(positive, (B * n) * power / safe, VZERO + 1e300);
    return cap_flow_stress(p, y, slope, factor);
  }
  return flow_stress(p, e, VZERO, VZERO, slope); /* capped; factor 1 */
}

/* Terms of the binomial series of (1 + x)^n used by near_flow_stress. */
#define BINOMIAL_TERMS 13

/* The binomial coefficients c[k] = n (n - 1) ... (n - k + 1) / k! of (1 + x)^n. */
INLINE void binomial_coefficients(double n, double c[BINOMIAL_TERMS])
{
  c[0] = 1.0;
  for (int k = 1; k < BINOMIAL_TERMS; ++k)
    c[k] = c[k - 1] * (n - (k - 1)) * (1.0 / k);
}

/* The flow stress and slope of capped_flow_stress at e = e0 (1 + x), 0 <= x <= 1/20, of a
 * power law (Johnson-Cook) whose power e0^n = power0 is known, inv_e0 = 1 / e0:
 * e^n = power0 (1 + x)^n by the binomial series c (binomial_coefficients) to x^12 (the
 * rest is below 1e-17 of the sum), no division and no exp/log in the Newton iterations
 * of a return.  The slope takes 1 / (1 + x) to x^5 (6e-9 at the bound): it only steers
 * Newton's steps, whose residual is that of the flow stress itself. */
INLINE vec near_flow_stress(const element_params *p, const double c[BINOMIAL_TERMS],
                            vec power0, vec inv_e0, vec x, vec factor, vec *slope)
{
  const double B = p->hardening_coefficient, n = p->hardening_exponent;
  vec series = VZERO + c[BINOMIAL_TERMS - 1];
  for (int k = BINOMIAL_TERMS - 2; k >= 0; --k)
    series = series * x + c[k];
  const vec power = power0 * series;
  const vec inverse = 1.0 - x * (1.0 - x * (1.0 - x * (1.0 - x * (1.0 - x))));
  *slope = (B * n) * power * inv_e0 * inverse;
  return cap_flow_stress(p, p->yield_stress + B * power, slope, factor);
}

/* capped_flow_stress, also giving e^n in *power (power laws; 1 otherwise) and 1 / e in
 * *inverse (1 where e <= 0, and for the other laws: only near_flow_stress needs it). */
INLINE vec flow_stress_power(const element_params *p, vec e, vec factor,
                             vec *slope, vec *power_out, vec *inverse)
{
  const ivec positive = e > 0.0;
  *inverse = VZERO + 1.0;
  *power_out = VZERO + 1.0;
  if (p->hardening == HARDENING_POWER || p->hardening == JOHNSON_COOK)
  {
    *inverse = 1.0 / vselect(positive, e, VZERO + 1.0);
    const double B = p->hardening_coefficient, n = p->hardening_exponent;
    const vec safe = vselect(positive, e, VZERO + 1.0);
    const vec power = n == 0.0 ? VZERO + 1.0 : vselect(positive, vexp(n * vlog(safe)), VZERO);
    *power_out = power;
    *slope = n == 0.0 ? VZERO : vselect(positive, (B * n) * power * *inverse, VZERO + 1e300);
    return cap_flow_stress(p, p->yield_stress + B * power, slope, factor);
  }
  return capped_flow_stress(p, e, factor, slope);
}

/* The square of the von Mises stress of a plane stress (xx, yy, xy; Pa^2). */
INLINE vec von_mises_squared(const vec sig[3])
{
  const vec pp = sig[0] + sig[1], dd = sig[1] - sig[0];
  return 0.25 * pp * pp + 0.75 * dd * dd + 3.0 * sig[2] * sig[2];
}

/* The exact plane-stress J2 return of the trial stresses sig[j][3] (xx, yy, xy; Pa, in/out)
 * of n points at once (a cell batch's points through the thickness: their Newton iterations
 * are independent chains the processor overlaps), at plastic strains eps_p[j], strain rates
 * rate[j] (1/s) and temperatures T[j] (K); q_old2[j] is the squared von Mises stress before
 * the step's increment.  Out: d[j] the plastic strain increment (0 in elastic lanes) and
 * flow[j] the flow stress after the step where it flowed (the von Mises stress of the
 * returned stress, equal to the law's value to about 1e-14; in elastic lanes the law's value
 * where it was needed, else 0).
 *
 * Elastic checks before any evaluation of the law: below A times the rate and temperature
 * factor (and the cap) for the laws whose flow stress never falls below it, and, for the
 * laws of eps_p alone, a trial stress not above the stress before the step (which was
 * admissible at the same eps_p).  Then g solves R(g) = sigma_y(e(g)) / q(g) - 1 = 0,
 * e(g) = eps_p + (2/3) g q(g): 1 / q(g) is linear in g for a deviatoric plane stress
 * (q = q_tr / (1 + 2 G g)), so that Newton's method on R converges in about two steps from
 * the start of its linearisation at g = 0, g0 = (q_tr - y0) / (c y0 + (2/3) h q_tr),
 * c = (k1 P1 + 2 G P2) / q_tr^2 (P1 = p^2 / 4, P2 = 3 d^2 / 4 + 3 sxy^2), h the slope of the
 * law at eps_p (the secant over the perfectly plastic increment at eps_p = 0, where a power
 * law's is infinite); kept in the bracket [0, (q_tr / y0 - 1) / k1], whose midpoint is
 * geometric while it spans decades.  It stops once |R| at the previous iterate is below 1e-7
 * (the step just taken leaves one of order 1e-14; 1e-13 from eps_p = 0, where the power
 * law's infinite slope makes the residual no guide to the next one's) or g moves by
 * round-off.  The power laws' flow stress in the iterations is near_flow_stress's series
 * about eps_p while the increment is below eps_p / 20, else exp and log. */
INLINE void plane_stress_returns(const element_params *p, const shell_params *s, int n,
                                 vec sig[][3], const vec eps_p[], const vec rate[],
                                 const vec T[], const vec q_old2[], vec d[], vec flow[])
{
  const double E = s->young, nu = s->poisson;
  const double k1 = E / (3.0 * (1.0 - nu)), g2 = E / (1.0 + nu);
  const int power_law = (p->hardening == HARDENING_POWER || p->hardening == JOHNSON_COOK)
                        && p->hardening_exponent != 0.0;
  const int of_eps_p = p->hardening != JOHNSON_COOK
                       || (p->rate_coefficient == 0.0 && !p->thermal);
  const double cap = p->max_flow_stress > 0.0 ? p->max_flow_stress : INFINITY;
  const double lowest = p->yield_stress < cap ? p->yield_stress : cap;
  /* Each stage below runs over all the points that need it before the next stage starts,
   * so that the points' dependency chains (square roots, divisions, the law's series)
   * overlap in the processor instead of running one after the other. */
  int m = 0, which[SHELL_MAX_POINTS], near[SHELL_MAX_POINTS];
  vec q2[SHELL_MAX_POINTS], factor[SHELL_MAX_POINTS], q_trial[SHELL_MAX_POINTS];
  vec y0[SHELL_MAX_POINTS], slope[SHELL_MAX_POINTS], power0[SHELL_MAX_POINTS];
  vec inv_e0[SHELL_MAX_POINTS];
  ivec maybe[SHELL_MAX_POINTS], plastic[SHELL_MAX_POINTS];
  /* the elastic checks: the points that may flow in some lane */
  for (int j = 0; j < n; ++j)
  {
    d[j] = flow[j] = VZERO;
    q2[j] = von_mises_squared(sig[j]);
    factor[j] = flow_factor(p, rate[j], T[j]);
    maybe[j] = q2[j] == q2[j]; /* every lane */
    if (p->hardening != HARDENING_TABLE)
    {
      const vec floor = lowest * factor[j];
      maybe[j] &= q2[j] > floor * floor;
    }
    if (of_eps_p)
      maybe[j] &= q2[j] > q_old2[j];
    if (any_lane(maybe[j]))
      which[m++] = j;
  }
  if (m == 0)
    return;
  /* the law at eps_p of those points, and their trial von Mises stresses */
  for (int a = 0; a < m; ++a)
  {
    const int j = which[a];
    q_trial[a] = vsqrt(q2[j]);
    y0[a] = flow_stress_power(p, eps_p[j], factor[j], &slope[a], &power0[a], &inv_e0[a]);
    flow[j] = y0[a];
  }
  /* the points that flow in some lane, packed in front */
  int flowing_points = 0;
  for (int a = 0; a < m; ++a)
  {
    const int j = which[a];
    const ivec flowing = maybe[j] & (q_trial[a] > y0[a]);
    if (!any_lane(flowing))
      continue;
    const int b = flowing_points++;
    which[b] = j;
    plastic[b] = flowing;
    factor[b] = factor[j];
    q_trial[b] = q_trial[a];
    y0[b] = y0[a];
    slope[b] = slope[a];
    power0[b] = power0[a];
    inv_e0[b] = inv_e0[a];
  }
  m = flowing_points;
  if (m == 0)
    return;
  vec pp[SHELL_MAX_POINTS], dd[SHELL_MAX_POINTS], P1[SHELL_MAX_POINTS], P2[SHELL_MAX_POINTS];
  vec g[SHELL_MAX_POINTS], lo[SHELL_MAX_POINTS], hi[SHELL_MAX_POINTS];
  vec tolerance[SHELL_MAX_POINTS];
  for (int a = 0; a < m; ++a)
  {
    const int j = which[a];
    const ivec flowing = plastic[a];
    const vec y = y0[a];
    pp[a] = sig[j][0] + sig[j][1];
    dd[a] = sig[j][1] - sig[j][0];
    P1[a] = 0.25 * pp[a] * pp[a];
    P2[a] = 0.75 * dd[a] * dd[a] + 3.0 * sig[j][2] * sig[j][2];
    const ivec virgin = flowing & (eps_p[j] <= 0.0);
    /* from eps_p = 0 a power law's slope is infinite and the residual no guide to the next
     * step's: iterate until it is itself at round-off */
    tolerance[a] = vselect(virgin, VZERO + 1e-13, VZERO + 1e-7);
    near[a] = power_law && !any_lane(virgin);
    const vec safe_q = vselect(flowing, q_trial[a], VZERO + 1.0);
    lo[a] = VZERO;
    hi[a] = (safe_q / vmax(y, VZERO + 1e-300) - 1.0) * (1.0 / k1);
    vec start = slope[a];
    if (any_lane(virgin))
    {
      const vec d0 = vmax((safe_q - y) * (1.0 / (1.5 * g2)), VZERO + 1e-300);
      vec unused;
      const vec secant = (capped_flow_stress(p, eps_p[j] + d0, factor[a], &unused) - y) / d0;
      start = vselect(eps_p[j] <= 0.0, secant, slope[a]);
    }
    const vec g0 = (safe_q - y) * (safe_q * safe_q)
                   / ((P1[a] * k1 + P2[a] * g2) * y
                      + (2.0 / 3.0) * vmax(start, VZERO) * (safe_q * safe_q * safe_q));
    g[a] = vselect(flowing, vmin(vmax(g0, VZERO), hi[a]), VZERO);
  }
  double binomial[BINOMIAL_TERMS] = {0.0}; /* of near_flow_stress: power laws only */
  if (power_law)
    binomial_coefficients(p->hardening_exponent, binomial);
  for (int iteration = 0; iteration < 50; ++iteration)
  {
    vec q[SHELL_MAX_POINTS], dq[SHELL_MAX_POINTS], rq[SHELL_MAX_POINTS];
    vec increment[SHELL_MAX_POINTS], y[SHELL_MAX_POINTS], h[SHELL_MAX_POINTS];
    int all_near = 1, use_series[SHELL_MAX_POINTS];
    for (int a = 0; a < m; ++a)
    {
      /* q = sqrt(W) / (A1 B1), W = P1 B1^2 + P2 A1^2: one division */
      const vec A1 = 1.0 + k1 * g[a], B1 = 1.0 + g2 * g[a], AB = A1 * B1;
      const vec root = vsqrt(P1[a] * B1 * B1 + P2[a] * A1 * A1);
      const vec inv = 1.0 / (root * AB);
      const vec r = root * inv, ra = B1 * r, rb = A1 * r; /* 1 / A1, 1 / B1 */
      rq[a] = AB * AB * inv;
      q[a] = root * r;
      dq[a] = -(P1[a] * k1 * ra * ra * ra + P2[a] * g2 * rb * rb * rb) * rq[a];
      increment[a] = (2.0 / 3.0) * g[a] * q[a];
      use_series[a] = near[a] && !any_lane(plastic[a] & (increment[a] > 0.05 * eps_p[which[a]]));
      all_near &= use_series[a];
    }
    if (all_near)
      for (int a = 0; a < m; ++a)
        y[a] = near_flow_stress(p, binomial, power0[a], inv_e0[a], increment[a] * inv_e0[a],
                                factor[a], &h[a]);
    else
      for (int a = 0; a < m; ++a)
        y[a] = use_series[a] ? near_flow_stress(p, binomial, power0[a], inv_e0[a],
                                          increment[a] * inv_e0[a], factor[a], &h[a])
                       : capped_flow_stress(p, eps_p[which[a]] + increment[a], factor[a], &h[a]);
    int more = 0;
    for (int a = 0; a < m; ++a)
    {
      const vec R = y[a] * rq[a] - 1.0;
      lo[a] = vselect(R < 0.0, g[a], lo[a]);
      hi[a] = vselect(R > 0.0, g[a], hi[a]);
      const vec dR = rq[a] * (vmax(h[a], VZERO) * (2.0 / 3.0) * (q[a] + g[a] * dq[a])
                              - y[a] * rq[a] * dq[a]);
      vec next = g[a] - R / dR;
      /* outside the bracket: its midpoint, geometric while it spans decades (the root of
       * a power law's infinite slope at eps_p = 0 may be many decades below the start) */
      const ivec outside = (next <= lo[a]) | (next >= hi[a]);
      if (any_lane(outside))
      {
        const vec middle = vselect(lo[a] < 1e-3 * hi[a],
                                   vsqrt(vmax(lo[a], 1e-30 * hi[a]) * hi[a]),
                                   0.5 * (lo[a] + hi[a]));
        next = vselect(outside, middle, next);
      }
      const vec change = vabs(next - g[a]);
      g[a] = vselect(plastic[a], next, VZERO);
      more |= any_lane(plastic[a] & (vabs(R) > tolerance[a])
                        & (change > 1e-15 * g[a] + 1e-300));
    }
    if (!more)
      break;
  }
  for (int a = 0; a < m; ++a)
  {
    const int j = which[a];
    const vec A1 = 1.0 + k1 * g[a], B1 = 1.0 + g2 * g[a];
    const vec r = 1.0 / (A1 * B1), ra = B1 * r, rb = A1 * r;
    const vec q = vsqrt(P1[a] * ra * ra + P2[a] * rb * rb);
    const vec p_new = pp[a] * ra, d_new = dd[a] * rb;
    const ivec on = plastic[a];
    sig[j][0] = vselect(on, 0.5 * (p_new - d_new), sig[j][0]);
    sig[j][1] = vselect(on, 0.5 * (p_new + d_new), sig[j][1]);
    sig[j][2] = vselect(on, sig[j][2] * rb, sig[j][2]);
    d[j] = vselect(on, (2.0 / 3.0) * g[a] * q, VZERO);
    flow[j] = vselect(on, q, y0[a]); /* on the yield surface after the return */
  }
}

/* One step at n through-thickness points: the stresses sig[j][3] (in/out), eps_p[j] and
 * T[j] (in/out) from the strain increments de[j][3] (xx, yy, gamma_xy) over p->dt; what the
 * step did in done[j] (for the failure criteria) and the plastic dissipation density
 * (J/m^3) in dissipation[j]. */
INLINE void shell_points_update(const element_params *p, const shell_params *s, int n,
                                vec sig[][3], vec eps_p[], vec T[], const vec de[][3],
                                point_step done[], vec dissipation[])
{
  vec rate[SHELL_MAX_POINTS], q_old2[SHELL_MAX_POINTS], d[SHELL_MAX_POINTS];
  vec flow[SHELL_MAX_POINTS];
  /* the strain rate: of Johnson-Cook's flow stress and of the failure criteria */
  const int uses_rate = p->hardening == JOHNSON_COOK || p->failure;
  for (int j = 0; j < n; ++j)
  {
    q_old2[j] = von_mises_squared(sig[j]);
    hooke_add(s, VZERO + 1.0, de[j], sig[j]);
    /* equivalent deviatoric strain rate with the incompressible thickness strain */
    const vec dz = -(de[j][0] + de[j][1]);
    const vec dd = de[j][0] * de[j][0] + de[j][1] * de[j][1] + dz * dz
                   + 0.5 * de[j][2] * de[j][2];
    rate[j] = p->dt > 0.0 && uses_rate ? vsqrt((2.0 / 3.0) * dd) * (1.0 / p->dt) : VZERO;
  }
  plane_stress_returns(p, s, n, sig, eps_p, rate, T, q_old2, d, flow);
  for (int j = 0; j < n; ++j)
  {
    eps_p[j] += d[j];
    dissipation[j] = flow[j] * d[j];
    done[j].increment = d[j];
    done[j].rate = rate[j];
    /* the failure criteria's (a division per point) */
    done[j].triaxiality = !p->failure ? VZERO
                          : vselect(d[j] > 0.0, ((1.0 / 3.0) * (sig[j][0] + sig[j][1]))
                                                    / vselect(d[j] > 0.0, flow[j], VZERO + 1.0),
                                    VZERO);
    if (p->thermal)
      T[j] += (p->taylor_quinney / (p->density * p->specific_heat)) * dissipation[j];
  }
}

/* The update of a batch's stress resultants over a step: from the membrane strain rates d,
 * curvature rates k (both (xx, yy, 2 xy)) and transverse shear rates gs (xz, yz), times
 * p->dt here, of cells of thickness t; the state rows as shell_quad.c says (elastic:
 * resultants; plastic: shear resultants and the points through the thickness).  Out: the
 * resultants N (N/m), M (N), Q (N/m) in the local frame, the stored elastic energy per unit
 * area (J/m^2; 0 when s->omit_energy), the plastic dissipation of the step per unit area
 * (J/m^2, with the elastic energy of points failing now), and 1 in the lanes whose share
 * of failed points has reached s->fail_fraction. */
INLINE void shell_update(int plastic, const element_params *p, const shell_params *s,
                         const batch_t *bp, double *restrict state, int64_t stride, vec t,
                         vec d[3], vec k[3], const vec gs[2], vec N[3], vec M[3], vec Q[2],
                         vec *elastic_out, vec *dissipated_out, vec *damage_out)
{
  const batch_t b = *bp;
  const double dt = p->dt, ks = s->shear_factor * 0.5 * s->young / (1.0 + s->poisson);
  const int npt = s->points;
  for (int i = 0; i < 3; ++i)
  {
    d[i] *= dt;
    k[i] *= dt;
  }
  for (int i = 0; i < 3; ++i)
    N[i] = M[i] = VZERO;
  vec elastic = VZERO, dissipated = VZERO, damage = VZERO;
  if (!plastic)
  {
    for (int i = 0; i < 3; ++i)
    {
      N[i] = load_slot(state, stride, &b, i);
      M[i] = load_slot(state, stride, &b, 3 + i);
    }
    Q[0] = load_slot(state, stride, &b, 6);
    Q[1] = load_slot(state, stride, &b, 7);
    hooke_add(s, t, d, N);
    hooke_add(s, (1.0 / 12.0) * t * t * t, k, M);
    for (int i = 0; i < 3; ++i)
    {
      store_slot(state, stride, &b, i, N[i]);
      store_slot(state, stride, &b, 3 + i, M[i]);
    }
    Q[0] += (ks * dt) * t * gs[0];
    Q[1] += (ks * dt) * t * gs[1];
    store_slot(state, stride, &b, 6, Q[0]);
    store_slot(state, stride, &b, 7, Q[1]);
    if (!s->omit_energy)
      elastic = compliance_product(s, N[0], N[1], N[2]) * (0.5 / t)
                + compliance_product(s, M[0], M[1], M[2]) * (6.0 / (t * t * t));
  }
  else
  {
    Q[0] = load_slot(state, stride, &b, 0) + (ks * dt) * t * gs[0];
    Q[1] = load_slot(state, stride, &b, 1) + (ks * dt) * t * gs[1];
    store_slot(state, stride, &b, 0, Q[0]);
    store_slot(state, stride, &b, 1, Q[1]);
    vec failed_points = VZERO;
    vec sig[SHELL_MAX_POINTS][3], eps_p[SHELL_MAX_POINTS], T[SHELL_MAX_POINTS];
    vec de[SHELL_MAX_POINTS][3], dissipation[SHELL_MAX_POINTS];
    point_step done[SHELL_MAX_POINTS];
    for (int pt = 0; pt < npt; ++pt)
    {
      const int base = 2 + SHELL_POINT_SLOTS * pt;
      const vec z = s->zeta[pt] * t;
      for (int i = 0; i < 3; ++i)
      {
        sig[pt][i] = load_slot(state, stride, &b, base + i);
        de[pt][i] = d[i] + z * k[i];
      }
      eps_p[pt] = load_slot(state, stride, &b, base + 3);
      /* the temperature changes, and matters, only with heating */
      T[pt] = p->thermal ? load_slot(state, stride, &b, base + 4) : VZERO;
    }
    shell_points_update(p, s, npt, sig, eps_p, T, de, done, dissipation);
    for (int pt = 0; pt < npt; ++pt)
    {
      const int base = 2 + SHELL_POINT_SLOTS * pt;
      const vec z = s->zeta[pt] * t, wt = s->weight[pt] * t;
      if (p->failure)
      {
        const vec D = load_slot(state, stride, &b, p->damage_slot + pt);
        const ivec dead = D >= 1.0;
        done[pt].increment = vselect(dead, VZERO, done[pt].increment);
        const vec D_new = vmax(D, accumulate_damage(p, state, stride, &b,
                                                    p->damage_slot + pt, &done[pt], T[pt]));
        const ivec gone = D_new >= 1.0;
        /* a point failing now gives up its elastic energy as dissipation */
        const vec held = 0.5 * compliance_product(s, sig[pt][0], sig[pt][1], sig[pt][2]);
        dissipation[pt] = vselect(dead, VZERO, dissipation[pt] + vselect(gone, held, VZERO));
        for (int i = 0; i < 3; ++i)
          sig[pt][i] = vselect(gone, VZERO, sig[pt][i]);
        failed_points += vselect(gone, VZERO + 1.0, VZERO);
      }
      for (int i = 0; i < 3; ++i)
      {
        store_slot(state, stride, &b, base + i, sig[pt][i]);
        N[i] += wt * sig[pt][i];
        M[i] += (wt * z) * sig[pt][i];
      }
      store_slot(state, stride, &b, base + 3, eps_p[pt]);
      if (p->thermal)
        store_slot(state, stride, &b, base + 4, T[pt]);
      if (!s->omit_energy)
        elastic += (0.5 * wt) * compliance_product(s, sig[pt][0], sig[pt][1], sig[pt][2]);
      dissipated += wt * dissipation[pt];
    }
    if (p->failure)
      damage = vselect(failed_points >= s->fail_fraction * npt - 1e-9, VZERO + 1.0, VZERO);
  }
  if (!s->omit_energy)
    elastic += (Q[0] * Q[0] + Q[1] * Q[1]) * (0.5 / ks) / t;
  *elastic_out = elastic;
  *dissipated_out = dissipated;
  *damage_out = damage;
}

/* The mean over the thickness of sxx + syy (Pa) of a batch's cells of thickness t, from the
 * state before shell_update: sum w_k (sxx + syy)_k, or (Nxx + Nyy) / t of elastic cells. */
INLINE vec shell_mean_stress(int plastic, const shell_params *s, const batch_t *b,
                             const double *restrict state, int64_t stride, vec t)
{
  if (!plastic)
    return (load_slot(state, stride, b, 0) + load_slot(state, stride, b, 1)) / t;
  vec sum = VZERO;
  for (int pt = 0; pt < s->points; ++pt)
  {
    const int base = 2 + SHELL_POINT_SLOTS * pt;
    sum += s->weight[pt] * (load_slot(state, stride, b, base) + load_slot(state, stride, b, base + 1));
  }
  return sum;
}

/* Ithick = 1: store the thickness of a batch's cells after the membrane strain increment d
 * (xx, yy, gamma_xy) over which their mean sxx + syy went from `before` to `after` (Pa):
 * ln(t'/t) = -(dxx + dyy) + (1 - 2 nu) / E (after - before), the plastic strain keeping the
 * volume and the elastic one changing it by (1 - 2 nu) / E times the sum of the stresses
 * (szz = 0), so that an elastic cell thins by nu / (1 - nu) (dxx + dyy). */
INLINE void shell_thickness_change(const shell_params *s, const batch_t *b, vec t, const vec d[3],
                                   vec before, vec after)
{
  const double bulk = (1.0 - 2.0 * s->poisson) / s->young;
  set_cell_values(s->new_thickness, b, t * vexp(bulk * (after - before) - (d[0] + d[1])));
}

#endif
