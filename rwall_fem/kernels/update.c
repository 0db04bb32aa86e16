/* The per-node parts of a central-difference step (docs/theory.md, "Time stepping").
 *
 * internal_acceleration: a = -f / m, the acceleration from the internal force f, before
 * body forces and constraints add to it or edit it; shell_acceleration: the same for a
 * shell body's translations and rotations in one sweep.
 *
 * central_difference: v^{n+1/2} = v^{n-1/2} + dt_v a^n, u^{n+1} = u^n + dt v^{n+1/2}, with
 * dt = dt^{n+1/2} and dt_v = (dt^{n-1/2} + dt^{n+1/2}) / 2 (a variable step), in one pass
 * that also returns what the energy books need of this step:
 *   out[0] = K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2}   (the shadow kinetic energy)
 *   out[1] = sum f . v^{n-1/2}, out[2] = sum f . v^{n+1/2}   (when f is given)
 *   out[3..5] = sum m v^{n-1/2}, out[6..8] = sum m v^{n+1/2}   (the work of uniform gravity)
 * and the momentum integral (kg m) of uniform gravity's work: with `integral` that of the
 * finished steps, momentum = integral + dt^n/2 out[3..5] (up to the first half of this
 * step), then integral += dt^n/2 (out[3..5] + out[6..8]);
 * (out[1] and out[2]: the mid-step booking of the internal work of materials without a
 * stored energy, and the energy correction of a varying step for the others); with
 * labels (a part per node, -1 at the interfaces of parts), the same two sums per part
 * over the nodes of that part alone, in part_sums[2 part] and part_sums[2 part + 1].
 *
 * shell_central_difference: the same pass over a shell body's nodes, each node's rotations
 * advanced in the same sweep as its translations (rwall_fem/shells/update.py):
 * w^{n+1/2} = w^{n-1/2} + dt_v alpha^n (angular velocity, global axes, rad/s), booking
 *   turns[0] = 1/2 sum I w^{n-1/2} . w^{n+1/2}   (the rotations' shadow kinetic energy; I the
 *              rotational inertia, inertia[2 i + 1] of the (n, 2) masses and inertias,
 *              times turning[i] when given: 0 at a rigid body's nodes)
 *   turns[1] = sum M . w^{n-1/2}, turns[2] = sum M . w^{n+1/2}   (M the nodal moments)
 * The rotations are angular velocities only: the elements take their frame from the
 * current coordinates, so there is no nodal triad to turn.
 *
 * interface_work: sum over k of f[k] . v[nodes[k]], the work rate (W) of a part's forces f
 * at the nodes it shares with other parts (rwall_fem/body.py).
 */
#include "batch.h"

/* No fused multiply-add here: v + dt a must round like the separate operations, so that a
 * prescribed velocity (a = (v_p - v)/dt) is met exactly. */
#pragma GCC optimize("fp-contract=off")

void internal_acceleration(int64_t n, const double *restrict f, const double *restrict inv_mass,
                double *restrict a)
{
#pragma omp simd
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      a[3 * i + c] = -f[3 * i + c] * inv_mass[i];
}

/* internal_acceleration of a shell body's translations and rotations in one sweep:
 * a = -f / m and alpha = -M / I (moments M, inv_inertia 1/I), the latter times free (0
 * where a rotation is held, 1 elsewhere; NULL: none held). */
void shell_acceleration(int64_t n, const double *restrict f, const double *restrict inv_mass,
                        double *restrict a, const double *restrict moments,
                        const double *restrict inv_inertia, const double *restrict free,
                        double *restrict alpha)
{
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
    {
      const int64_t j = 3 * i + c;
      const double turn = -moments[j] * inv_inertia[i];
      a[j] = -f[j] * inv_mass[i];
      alpha[j] = free ? turn * free[j] : turn;
    }
}

/* One node of the update (f: NULL or the booked force); kept inline so that each loop
 * below is compiled for its case. */
INLINE void advance_node(int64_t i, double dt_v, double dt, const double *restrict mass,
                         const double *restrict a, double *restrict v, double *restrict u,
                         const double *restrict f, double *kinetic, double *first,
                         double *second, double before[3], double after[3],
                         const int32_t *restrict labels, double *restrict part_sums)
{
  const double m = mass[i];
  double mine[2] = {0.0, 0.0};
  for (int c = 0; c < 3; ++c)
  {
    const int64_t j = 3 * i + c;
    const double old = v[j], next = old + dt_v * a[j];
    *kinetic += m * old * next;
    if (f)
    {
      mine[0] += f[j] * old;
      mine[1] += f[j] * next;
    }
    before[c] += m * old;
    after[c] += m * next;
    v[j] = next;
    u[j] += dt * next;
  }
  if (f)
  {
    *first += mine[0];
    *second += mine[1];
    if (labels && labels[i] >= 0)
    {
      part_sums[2 * labels[i]] += mine[0];
      part_sums[2 * labels[i] + 1] += mine[1];
    }
  }
}

/* The pass's sums into out[9] and the momentum integral (see central_difference). */
INLINE void finish(double dt_v, double kinetic, double first, double second,
                   const double before[3], const double after[3], double out[9],
                   double integral[3], double momentum[3])
{
  out[0] = 0.5 * kinetic;
  out[1] = first;
  out[2] = second;
  const double half = 0.5 * dt_v;
  for (int c = 0; c < 3; ++c)
  {
    out[3 + c] = before[c];
    out[6 + c] = after[c];
    momentum[c] = integral[c] + half * before[c];
    integral[c] += half * (before[c] + after[c]);
  }
}

void central_difference(int64_t n, double dt_v, double dt, const double *restrict mass,
                        const double *restrict a, double *restrict v, double *restrict u,
                        const double *restrict f, double out[9], double integral[3],
                        double momentum[3], const int32_t *restrict labels,
                        double *restrict part_sums)
{
  double kinetic = 0.0, first = 0.0, second = 0.0, before[3] = {0.0, 0.0, 0.0},
         after[3] = {0.0, 0.0, 0.0};
  if (f && labels)
    for (int64_t i = 0; i < n; ++i)
      advance_node(i, dt_v, dt, mass, a, v, u, f, &kinetic, &first, &second, before, after,
                   labels, part_sums);
  else if (f)
    for (int64_t i = 0; i < n; ++i)
      advance_node(i, dt_v, dt, mass, a, v, u, f, &kinetic, &first, &second, before, after,
                   NULL, NULL);
  else
    for (int64_t i = 0; i < n; ++i)
      advance_node(i, dt_v, dt, mass, a, v, u, NULL, &kinetic, &first, &second, before, after,
                   NULL, NULL);
  finish(dt_v, kinetic, first, second, before, after, out, integral, momentum);
}

/* One node's rotations (see shell_central_difference). */
INLINE void advance_rotation(int64_t i, double dt_v, const double *restrict inertia,
                             const double *restrict turning, const double *restrict alpha,
                             const double *restrict moments, double *restrict w,
                             double turns[3])
{
  const double I = turning ? inertia[2 * i + 1] * turning[i] : inertia[2 * i + 1];
  for (int c = 0; c < 3; ++c)
  {
    const int64_t j = 3 * i + c;
    const double old = w[j], next = old + dt_v * alpha[j];
    turns[0] += I * old * next;
    turns[1] += moments[j] * old;
    turns[2] += moments[j] * next;
    w[j] = next;
  }
}

void shell_central_difference(int64_t n, double dt_v, double dt, const double *restrict mass,
                              const double *restrict a, double *restrict v, double *restrict u,
                              const double *restrict f, double out[9], double integral[3],
                              double momentum[3], const int32_t *restrict labels,
                              double *restrict part_sums, const double *restrict inertia,
                              const double *restrict turning, const double *restrict alpha,
                              const double *restrict moments, double *restrict w,
                              double turns[3])
{
  double kinetic = 0.0, first = 0.0, second = 0.0, before[3] = {0.0, 0.0, 0.0},
         after[3] = {0.0, 0.0, 0.0}, sums[3] = {0.0, 0.0, 0.0};
  for (int64_t i = 0; i < n; ++i)
  {
    advance_node(i, dt_v, dt, mass, a, v, u, f, &kinetic, &first, &second, before, after,
                 labels, part_sums);
    advance_rotation(i, dt_v, inertia, turning, alpha, moments, w, sums);
  }
  finish(dt_v, kinetic, first, second, before, after, out, integral, momentum);
  turns[0] = 0.5 * sums[0];
  turns[1] = sums[1];
  turns[2] = sums[2];
}

double interface_work(int64_t n, const int32_t *restrict nodes, const double *restrict f,
                      const double *restrict v)
{
  double sum = 0.0;
  for (int64_t k = 0; k < n; ++k)
  {
    const double *vk = v + 3 * (int64_t)nodes[k];
    sum += f[3 * k] * vk[0] + f[3 * k + 1] * vk[1] + f[3 * k + 2] * vk[2];
  }
  return sum;
}
