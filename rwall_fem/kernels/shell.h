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
 *     F(g) = q(g) - sigma_y(eps_p + (2/3) g q(g)) = 0,
 * F decreasing in g: Newton's method kept inside the bracket [0, (q_tr / sigma_y0 - 1) / k1]
 * (q(g) <= q_tr / (1 + k1 g) since k1 <= 2 G for nu <= 1/2).  The normal stress through
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
} shell_params;

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

/* The flow stress and slope of capped_flow_stress at e = e0 (1 + x), 0 <= x <= 1/20, of a
 * power law (Johnson-Cook) whose power e0^n = power0 is known: e^n = power0 (1 + x)^n with
 * log(1 + x) = 2 atanh(x / (2 + x)) and the exponential by their series (to about one ulp),
 * a third of the cost of exp(n log e) in the Newton iterations of a return. */
INLINE vec near_flow_stress(const element_params *p, vec e0, vec power0,
                            vec e, vec factor, vec *slope)
{
  const double B = p->hardening_coefficient, n = p->hardening_exponent;
  const vec x = (e - e0) / e0, w = x / (2.0 + x), w2 = w * w;
  /* log(1 + x) = 2 (w + w^3/3 + ... + w^13/13), w <= 1/41 */
  vec series = VZERO + 1.0 / 13.0;
  for (int k = 5; k >= 0; --k)
    series = series * w2 + 1.0 / (2 * k + 1);
  const vec t = (2.0 * n) * w * series; /* n log(1 + x) <= 0.049 */
  vec ex = VZERO + 1.0 / 3628800.0;
  double factorial = 3628800.0;
  for (int k = 9; k >= 0; --k)
  {
    factorial /= (k + 1);
    ex = ex * t + 1.0 / factorial;
  }
  const vec power = power0 * ex;
  *slope = (B * n) * power / e;
  return cap_flow_stress(p, p->yield_stress + B * power, slope, factor);
}

/* capped_flow_stress, also giving e^n in *power (power laws; 1 otherwise). */
INLINE vec flow_stress_power(const element_params *p, vec e, vec factor,
                             vec *slope, vec *power_out)
{
  *power_out = VZERO + 1.0;
  if (p->hardening == HARDENING_POWER || p->hardening == JOHNSON_COOK)
  {
    const double B = p->hardening_coefficient, n = p->hardening_exponent;
    const ivec positive = e > 0.0;
    const vec safe = vselect(positive, e, VZERO + 1.0);
    const vec power = n == 0.0 ? VZERO + 1.0 : vselect(positive, vexp(n * vlog(safe)), VZERO);
    *power_out = power;
    *slope = n == 0.0 ? VZERO : vselect(positive, (B * n) * power / safe, VZERO + 1e300);
    return cap_flow_stress(p, p->yield_stress + B * power, slope, factor);
  }
  return capped_flow_stress(p, e, factor, slope);
}

/* The exact plane-stress J2 return of the trial stress sig[3] (xx, yy, xy; Pa, in/out) at
 * plastic strain eps_p, strain rate `rate` (1/s) and temperature T (K): returns the plastic
 * strain increment (0 in elastic lanes); *flow = the flow stress after the step where it
 * flowed (the von Mises stress of the returned stress, equal to it to about 1e-14; not set to the
 * law's value in lanes that stay elastic). */
INLINE vec plane_stress_return(const element_params *p, const shell_params *s, vec sig[3],
                               vec eps_p, vec rate, vec T, vec *flow)
{
  const vec factor = flow_factor(p, rate, T);
  const double E = s->young, nu = s->poisson;
  const double k1 = E / (3.0 * (1.0 - nu)), g2 = E / (1.0 + nu);
  const vec pp = sig[0] + sig[1], dd = sig[1] - sig[0], xy = sig[2];
  const vec P1 = 0.25 * pp * pp, P2 = 0.75 * dd * dd + 3.0 * xy * xy;
  const vec q_trial = vsqrt(P1 + P2);
  /* below A factor (and the cap) every lane is elastic for the laws whose flow stress never
   * falls below it (linear and power hardening, Johnson-Cook): no evaluation of the law */
  if (p->hardening != HARDENING_TABLE)
  {
    const double cap = p->max_flow_stress > 0.0 ? p->max_flow_stress : INFINITY;
    const vec floor = fmin(p->yield_stress, cap) * factor;
    if (!any_lane(q_trial > floor))
    {
      *flow = VZERO;
      return VZERO;
    }
  }
  vec slope, power0;
  const vec y0 = flow_stress_power(p, eps_p, factor, &slope, &power0);
  const int power_law = (p->hardening == HARDENING_POWER || p->hardening == JOHNSON_COOK)
                        && p->hardening_exponent != 0.0;
  const ivec plastic = q_trial > y0;
  *flow = y0;
  if (!any_lane(plastic))
    return VZERO;
  /* F(0) = q_tr - y0 > 0; first guess from the linearisation at g = 0 with the secant
   * slope of the flow stress over the perfectly plastic increment (q_tr - y0) / 3G (the
   * tangent of a power law is infinite at eps_p = 0) */
  const vec safe_q = vselect(plastic, q_trial, VZERO + 1.0);
  vec lo = VZERO, hi = (safe_q / vmax(y0, VZERO + 1e-300) - 1.0) * (1.0 / k1);
  vec start = slope;
  if (any_lane(plastic & (eps_p <= 0.0)))
  {
    const vec d0 = vmax((safe_q - y0) * (1.0 / (1.5 * g2)), VZERO + 1e-300);
    vec unused;
    const vec secant = (capped_flow_stress(p, eps_p + d0, factor, &unused) - y0) / d0;
    start = vselect(eps_p <= 0.0, secant, slope);
  }
  vec g = (safe_q - y0)
          / ((P1 * k1 + P2 * g2) / safe_q + (2.0 / 3.0) * vmax(start, VZERO) * safe_q);
  g = vselect(plastic, vmin(vmax(g, VZERO), hi), VZERO);
  vec q = safe_q;
  for (int iteration = 0; iteration < 50; ++iteration)
  {
    const vec a = 1.0 / (1.0 + k1 * g), b = 1.0 / (1.0 + g2 * g);
    q = vsqrt(P1 * a * a + P2 * b * b);
    const vec dq = -(P1 * k1 * a * a * a + P2 * g2 * b * b * b) / q;
    const vec e = eps_p + (2.0 / 3.0) * g * q;
    vec h;
    /* near eps_p (a step's increment, once flowing): the series about it */
    const int near = power_law && !any_lane(plastic & ((eps_p <= 0.0) | (e > 1.05 * eps_p)));
    const vec F = q - (near ? near_flow_stress(p, vmax(eps_p, VZERO + 1e-300), power0, e,
                                               factor, &h)
                            : capped_flow_stress(p, e, factor, &h));
    lo = vselect(F > 0.0, g, lo);
    hi = vselect(F < 0.0, g, hi);
    const vec dF = dq - vmax(h, VZERO) * (2.0 / 3.0) * (q + g * dq);
    vec next = g - F / dF;
    next = vselect((next <= lo) | (next >= hi), 0.5 * (lo + hi), next);
    const vec change = vabs(next - g);
    g = vselect(plastic, next, VZERO);
    /* converged: the residual at the previous g was below 1e-7 q, so that the Newton step
     * just taken (quadratic convergence) leaves one of order 1e-14 q; or g moves by round-off */
    if (!any_lane(plastic & (vabs(F) > 1e-7 * q) & (change > 1e-15 * g + 1e-300)))
      break;
  }
  const vec a = 1.0 / (1.0 + k1 * g), b = 1.0 / (1.0 + g2 * g);
  q = vsqrt(P1 * a * a + P2 * b * b);
  const vec p_new = pp * a, d_new = dd * b;
  sig[0] = 0.5 * (p_new - d_new);
  sig[1] = 0.5 * (p_new + d_new);
  sig[2] = xy * b;
  const vec d = vselect(plastic, (2.0 / 3.0) * g * q, VZERO);
  *flow = vselect(plastic, q, y0); /* on the yield surface after the return */
  return d;
}

/* One step at a through-thickness point: the stress sig[3] (in/out), eps_p and T (in/out)
 * from the strain increment de[3] (xx, yy, gamma_xy) over p->dt; what the step did in
 * *done (for the failure criteria).  Returns the plastic dissipation density (J/m^3). */
INLINE vec shell_point_update(const element_params *p, const shell_params *s, vec sig[3],
                              vec *eps_p, vec *T, const vec de[3], point_step *done)
{
  hooke_add(s, VZERO + 1.0, de, sig);
  /* equivalent deviatoric strain rate with the incompressible thickness strain */
  const vec dz = -(de[0] + de[1]);
  const vec dd = de[0] * de[0] + de[1] * de[1] + dz * dz + 0.5 * de[2] * de[2];
  const vec rate = p->dt > 0.0 ? vsqrt((2.0 / 3.0) * dd) * (1.0 / p->dt) : VZERO;
  vec flow;
  const vec d = plane_stress_return(p, s, sig, *eps_p, rate, *T, &flow);
  *eps_p += d;
  const vec dissipation = flow * d;
  done->increment = d;
  done->rate = rate;
  done->triaxiality = vselect(d > 0.0, ((1.0 / 3.0) * (sig[0] + sig[1])) / flow, VZERO);
  if (p->thermal)
    *T += (p->taylor_quinney / (p->density * p->specific_heat)) * dissipation;
  return dissipation;
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
    for (int pt = 0; pt < npt; ++pt)
    {
      const int base = 2 + SHELL_POINT_SLOTS * pt;
      const vec z = s->zeta[pt] * t, wt = s->weight[pt] * t;
      vec sig[3], eps_p, T, de[3];
      for (int i = 0; i < 3; ++i)
      {
        sig[i] = load_slot(state, stride, &b, base + i);
        de[i] = d[i] + z * k[i];
      }
      eps_p = load_slot(state, stride, &b, base + 3);
      T = load_slot(state, stride, &b, base + 4);
      vec D = VZERO;
      if (p->failure)
        D = load_slot(state, stride, &b, p->damage_slot + pt);
      const ivec dead = D >= 1.0;
      point_step done;
      vec dissipation = shell_point_update(p, s, sig, &eps_p, &T, de, &done);
      if (p->failure)
      {
        done.increment = vselect(dead, VZERO, done.increment);
        const vec D_new = vmax(D, accumulate_damage(p, state, stride, &b,
                                                    p->damage_slot + pt, &done, T));
        const ivec gone = D_new >= 1.0;
        /* a point failing now gives up its elastic energy as dissipation */
        const vec held = 0.5 * compliance_product(s, sig[0], sig[1], sig[2]);
        dissipation = vselect(dead, VZERO, dissipation + vselect(gone, held, VZERO));
        for (int i = 0; i < 3; ++i)
          sig[i] = vselect(gone, VZERO, sig[i]);
        failed_points += vselect(gone, VZERO + 1.0, VZERO);
      }
      for (int i = 0; i < 3; ++i)
      {
        store_slot(state, stride, &b, base + i, sig[i]);
        N[i] += wt * sig[i];
        M[i] += (wt * z) * sig[i];
      }
      store_slot(state, stride, &b, base + 3, eps_p);
      store_slot(state, stride, &b, base + 4, T);
      if (!s->omit_energy)
        elastic += (0.5 * wt) * compliance_product(s, sig[0], sig[1], sig[2]);
      dissipated += wt * dissipation;
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
