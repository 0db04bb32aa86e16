/* J2 (von Mises) elasto-plasticity, hypoelastic, at one integration point.
 *
 * The update of a step (docs/theory.md, "Plasticity"): from the displacement
 * increment's gradient dL = grad(du) in the mid-step configuration,
 * 1. rotate the stress with the increment's spin W = skew(dL) (Hughes-Winget:
 *    R = I + 2 (K + K^2) / (1 + a.a), K the skew matrix of a = axial(W)/2,
 *    sigma* = R sigma R^T; the Jaumann rate, incrementally objective);
 * 2. elastic predictor sigma_trial = sigma* + lambda tr(de) I + 2 mu de, de = sym(dL);
 * 3. radial return: q_trial = sqrt(3/2 s:s) of the deviator s; if q_trial exceeds
 *    the flow stress sigma_y(eps_p), the plastic increment d solves
 *    q_trial - 3 mu d = sigma_y(eps_p + d) (closed form for linear hardening, else
 *    Newton's method kept inside the bracket [0, q_trial / (3 mu)]) and
 *    s = s_trial (1 - 3 mu d / q_trial); the pressure stays elastic.
 * Flow stress: linear A + H eps_p; power law A + B eps_p^n; a table (eps_p,
 * sigma_y) interpolated linearly, constant beyond its last row; Johnson-Cook
 * (A + B eps_p^n)(1 + C ln max(rate / rate_0, 1))(1 - T*^m), with rate the
 * equivalent deviatoric strain rate of the step and T* = (T - T_room) /
 * (T_melt - T_room) clipped to [0, 1]; the law (before those factors) capped at
 * max_flow_stress (slope 0 where the cap holds); adiabatic heating (when thermal) raises T
 * by taylor_quinney sigma_y d / (density specific_heat).
 * Symmetric tensors are stored as (xx, yy, zz, xy, yz, xz).
 */
#ifndef RWALL_PLASTICITY_H
#define RWALL_PLASTICITY_H

#include "batch.h"

enum
{
  HARDENING_LINEAR = 0,
  HARDENING_POWER = 1,
  HARDENING_TABLE = 2,
  JOHNSON_COOK = 3
};

/* Slots of one integration point in the state array: stress (6), eps_p, temperature. */
#define POINT_SLOTS 8

INLINE vec vpow(vec x, double n)
{
  vec r;
  for (int k = 0; k < LANES; ++k)
    r[k] = n == 0.0 ? 1.0 : pow(x[k], n);
  return r;
}

/* The law's value y (Pa) and slope *slope at a plastic strain, capped at p->max_flow_stress
 * (Radioss LAW2's SIG_max0 with its default ICC = 1: the cap applies to the hardening law,
 * before Johnson-Cook's rate and temperature `factor`), times the factor: min(y, cap) factor,
 * slope 0 where the cap holds.  No cap (0) takes no comparison. */
INLINE vec cap_flow_stress(const element_params *p, vec y, vec *slope, vec factor)
{
  if (p->max_flow_stress > 0.0)
  {
    const ivec capped = y > p->max_flow_stress;
    *slope = vselect(capped, VZERO, *slope);
    y = vselect(capped, VZERO + p->max_flow_stress, y);
  }
  *slope *= factor;
  return y * factor;
}

/* Flow stress sigma_y (Pa) at plastic strain e, strain rate (1/s) and temperature T (K),
 * capped (cap_flow_stress); *slope = d sigma_y / d e. */
INLINE vec flow_stress(const element_params *p, vec e, vec rate, vec T, vec *slope)
{
  const double A = p->yield_stress;
  if (p->hardening == HARDENING_LINEAR)
  {
    *slope = VZERO + p->hardening_modulus;
    return cap_flow_stress(p, A + p->hardening_modulus * e, slope, VZERO + 1.0);
  }
  if (p->hardening == HARDENING_TABLE)
  {
    const int n = p->table_size;
    vec value = VZERO + p->table_stress[0], s = VZERO;
    for (int j = 0; j + 1 < n; ++j)
    {
      const double e0 = p->table_strain[j], e1 = p->table_strain[j + 1];
      const double k = (p->table_stress[j + 1] - p->table_stress[j]) / (e1 - e0);
      const ivec in = e >= e0;
      value = vselect(in, p->table_stress[j] + k * (vmin(e, VZERO + e1) - e0), value);
      s = vselect(in & (e < e1), VZERO + k, vselect(in, VZERO, s));
    }
    *slope = s;
    return cap_flow_stress(p, value, slope, VZERO + 1.0);
  }
  /* power law and Johnson-Cook: A + B e^n times the rate and temperature factors */
  const double B = p->hardening_coefficient, n = p->hardening_exponent;
  const vec power = vpow(e, n);
  const vec base = A + B * power;
  *slope = n == 0.0 ? VZERO : (B * n) * vpow(vmax(e, VZERO + 1e-300), n - 1.0);
  vec factor = VZERO + 1.0;
  if (p->hardening == JOHNSON_COOK)
  {
    factor += p->rate_coefficient * vlog(vmax(rate * (1.0 / p->reference_rate), VZERO + 1.0));
    if (p->thermal)
    {
      const vec star = vmin(vmax((T - p->room_temperature)
                                     * (1.0 / (p->melting_temperature - p->room_temperature)),
                                 VZERO),
                            VZERO + 1.0);
      factor *= 1.0 - vpow(star, p->thermal_exponent);
    }
  }
  return cap_flow_stress(p, base, slope, factor);
}

/* The Hughes-Winget rotation R (row-major) of the spin increment W = skew(dL). */
INLINE void rotation(const vec dL[9], vec R[9])
{
  const vec a[3] = {0.25 * (dL[7] - dL[5]), 0.25 * (dL[2] - dL[6]), 0.25 * (dL[3] - dL[1])};
  const vec c = 2.0 / (1.0 + dot3(a, a));
  const vec K[9] = {VZERO, -a[2], a[1], a[2], VZERO, -a[0], -a[1], a[0], VZERO};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      const vec KK = K[3 * i] * K[j] + K[3 * i + 1] * K[3 + j] + K[3 * i + 2] * K[6 + j];
      R[3 * i + j] = c * (K[3 * i + j] + KK) + (i == j ? 1.0 : 0.0);
    }
}

/* sigma <- R sigma R^T with R the Hughes-Winget rotation of the spin increment skew(dL). */
INLINE void rotate(vec sigma[9], const vec dL[9])
{
  vec R[9], RS[9];
  rotation(dL, R);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      RS[3 * i + j] = R[3 * i] * sigma[j] + R[3 * i + 1] * sigma[3 + j] + R[3 * i + 2] * sigma[6 + j];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
    {
      sigma[3 * i + j] = RS[3 * i] * R[3 * j] + RS[3 * i + 1] * R[3 * j + 1] + RS[3 * i + 2] * R[3 * j + 2];
      sigma[3 * j + i] = sigma[3 * i + j];
    }
}

/* What a step did at a point, for the failure criteria (failure.h). */
typedef struct
{
  vec increment;   /* d, the plastic strain increment (0 where the step was elastic) */
  vec rate;        /* the equivalent strain rate of the step, 1/s */
  vec triaxiality; /* mean stress / von Mises stress after the return (where d > 0) */
} point_step;

/* One step of the material at a point: the stress sigma[9] (Pa, in/out), the plastic
 * strain *eps_p and temperature *T (in/out) from the increment gradient dL[9] over dt;
 * what the step did in *done.  Returns the plastic dissipation density (J/m^3) of the
 * step, sigma_y d. */
INLINE vec plastic_update(const element_params *p, vec sigma[9], vec *eps_p, vec *T,
                          const vec dL[9], point_step *done)
{
  const double mu = p->mu, lambda = p->lmbda;
  rotate(sigma, dL);
  vec de[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      de[3 * i + j] = 0.5 * (dL[3 * i + j] + dL[3 * j + i]);
  const vec tr_de = de[0] + de[4] + de[8];
  for (int i = 0; i < 9; ++i)
    sigma[i] += 2.0 * mu * de[i] + (i % 4 == 0 ? lambda * tr_de : VZERO);
  const vec pressure = (1.0 / 3.0) * (sigma[0] + sigma[4] + sigma[8]);
  vec s[9], ss = VZERO, dd = VZERO;
  for (int i = 0; i < 9; ++i)
  {
    s[i] = i % 4 == 0 ? sigma[i] - pressure : sigma[i];
    ss += s[i] * s[i];
    const vec dev = i % 4 == 0 ? de[i] - (1.0 / 3.0) * tr_de : de[i];
    dd += dev * dev;
  }
  const vec q_trial = vsqrt(1.5 * ss);
  const vec rate = p->dt > 0.0 ? vsqrt((2.0 / 3.0) * dd) * (1.0 / p->dt) : VZERO;
  vec slope;
  const vec yield = flow_stress(p, *eps_p, rate, *T, &slope);
  const ivec plastic = q_trial > yield;
  done->increment = done->triaxiality = VZERO;
  done->rate = rate;
  if (!any_lane(plastic))
    return VZERO;
  vec d;
  if (p->hardening == HARDENING_LINEAR)
  {
    /* closed form along the line (slope 0 if already at the cap), and from the cap on if the
     * line crosses it within the step */
    d = (q_trial - yield) / (3.0 * mu + slope);
    if (p->max_flow_stress > 0.0)
      d = vselect(yield + slope * d > p->max_flow_stress,
                  (q_trial - p->max_flow_stress) * (1.0 / (3.0 * mu)), d);
  }
  else
  {
    /* Newton on r(d) = q_trial - 3 mu d - sigma_y(eps_p + d), kept in [lo, hi]. */
    vec lo = VZERO, hi = q_trial * (1.0 / (3.0 * mu));
    d = (q_trial - yield) / (3.0 * mu + vmax(slope, VZERO));
    d = vmin(d, hi);
    for (int iteration = 0; iteration < 60; ++iteration)
    {
      vec h;
      const vec r = q_trial - 3.0 * mu * d - flow_stress(p, *eps_p + d, rate, *T, &h);
      lo = vselect(r > 0.0, d, lo);
      hi = vselect(r < 0.0, d, hi);
      vec next = d + r / (3.0 * mu + vmax(h, VZERO));
      const ivec outside = (next <= lo) | (next >= hi);
      next = vselect(outside, 0.5 * (lo + hi), next);
      const vec change = vabs(next - d);
      d = next;
      if (!any_lane(plastic & (change > 1e-15 * (*eps_p + d) + 1e-300)))
        break;
    }
  }
  d = vselect(plastic, d, VZERO);
  vec final_yield, unused;
  const vec scale = vselect(plastic, 1.0 - 3.0 * mu * d / q_trial, VZERO + 1.0);
  for (int i = 0; i < 9; ++i)
    sigma[i] = i % 4 == 0 ? s[i] * scale + pressure : s[i] * scale;
  *eps_p += d;
  final_yield = flow_stress(p, *eps_p, rate, *T, &unused);
  const vec dissipation = final_yield * d;
  done->increment = d;
  /* after the return the von Mises stress is the flow stress, positive where d > 0 */
  done->triaxiality = pressure / vselect(plastic, final_yield, VZERO + 1.0);
  if (p->thermal)
    *T += (p->taylor_quinney / (p->density * p->specific_heat)) * dissipation;
  return dissipation;
}

/* Stored elastic energy density (J/m^3) of a stress: s:s / (4 mu) + p^2 / (2 K). */
INLINE vec elastic_energy_density(const element_params *p, const vec sigma[9])
{
  const double bulk = p->lmbda + 2.0 / 3.0 * p->mu;
  const vec pressure = (1.0 / 3.0) * (sigma[0] + sigma[4] + sigma[8]);
  vec ss = VZERO;
  for (int i = 0; i < 9; ++i)
  {
    const vec s = i % 4 == 0 ? sigma[i] - pressure : sigma[i];
    ss += s * s;
  }
  return ss * (1.0 / (4.0 * p->mu)) + pressure * pressure * (1.0 / (2.0 * bulk));
}

/* Slot `slot` of the batch's cells in the state (slot k of cell c at state[k * stride + c]). */
INLINE vec load_slot(const double *restrict state, int64_t stride, const batch_t *b, int slot)
{
  return cell_values(state + slot * stride, b);
}

INLINE void store_slot(double *restrict state, int64_t stride, const batch_t *b, int slot, vec v)
{
  set_cell_values(state + slot * stride, b, v);
}

/* The POINT_SLOTS values of the batch's cells from slot `base` of the state. */
INLINE void load_point(const double *restrict state, int64_t stride, const batch_t *b, int base,
                       vec sigma[9], vec *eps_p, vec *T)
{
  vec v[POINT_SLOTS];
  for (int slot = 0; slot < POINT_SLOTS; ++slot)
    v[slot] = load_slot(state, stride, b, base + slot);
  sigma[0] = v[0], sigma[4] = v[1], sigma[8] = v[2];
  sigma[1] = sigma[3] = v[3];
  sigma[5] = sigma[7] = v[4];
  sigma[2] = sigma[6] = v[5];
  *eps_p = v[6];
  *T = v[7];
}

INLINE void store_point(double *restrict state, int64_t stride, const batch_t *b, int base,
                        const vec sigma[9], vec eps_p, vec T)
{
  const vec v[POINT_SLOTS] = {sigma[0], sigma[4], sigma[8], sigma[1],
                              sigma[5], sigma[2], eps_p,    T};
  for (int slot = 0; slot < POINT_SLOTS; ++slot)
    store_slot(state, stride, b, base + slot, v[slot]);
}

#endif
