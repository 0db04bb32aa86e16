/* The per-node parts of a central-difference step (docs/theory.md, "Time stepping").
 *
 * accelerate: a = -f / m, the acceleration from the internal force f, before
 * body forces and constraints add to it or edit it.
 *
 * advance: v^{n+1/2} = v^{n-1/2} + dt a^n, u^{n+1} = u^n + dt v^{n+1/2}, in one
 * pass that also returns what the energy books need of this step:
 *   out[0] = K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2}   (the shadow kinetic energy)
 *   out[1] = dt/2 sum f . v^{n-1/2}                  (first half of the work of f)
 *   out[2] = dt/2 sum f . v^{n+1/2}                  (second half)
 * (out[1] and out[2] only when f is given; the mid-step booking of the internal
 * work for materials without a stored energy).
 */
#include "batch.h"

void accelerate(int64_t n, const double *restrict f, const double *restrict inv_mass,
                double *restrict a)
{
#pragma omp simd
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      a[3 * i + c] = -f[3 * i + c] * inv_mass[i];
}

void advance(int64_t n, double dt, const double *restrict mass, const double *restrict a,
             double *restrict v, double *restrict u, const double *restrict f, double out[3])
{
  double kinetic = 0.0, first = 0.0, second = 0.0;
  if (f)
  {
#pragma omp simd reduction(+ : kinetic, first, second)
    for (int64_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
      {
        const int64_t j = 3 * i + c;
        const double old = v[j], next = old + dt * a[j];
        kinetic += mass[i] * old * next;
        first += f[j] * old;
        second += f[j] * next;
        v[j] = next;
        u[j] += dt * next;
      }
  }
  else
  {
#pragma omp simd reduction(+ : kinetic)
    for (int64_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
      {
        const int64_t j = 3 * i + c;
        const double old = v[j], next = old + dt * a[j];
        kinetic += mass[i] * old * next;
        v[j] = next;
        u[j] += dt * next;
      }
  }
  out[0] = 0.5 * kinetic;
  out[1] = 0.5 * dt * first;
  out[2] = 0.5 * dt * second;
}
