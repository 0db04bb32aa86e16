/* Elastic constitutive laws at one integration point, from the displacement
 * gradient L = grad u (row-major 3 x 3, L[3 i + j] = du_i/dX_j).
 *
 * stress() returns the energy density (J/m^3) and writes T (row-major), the
 * stress whose product with a shape-function gradient gives the nodal force:
 * f_I = V T b_I.  Small strain: T is the Cauchy stress of Hooke's law and
 * b the gradient in the (fixed) configuration.  Total Lagrangian: T is the
 * first Piola-Kirchhoff stress P(F), F = I + L, and b the gradient in the
 * reference configuration.  The formulas are written out in docs/theory.md
 * (elements); they are those of rwall_fem.hyperelasticity, the UFL
 * reference the tests compare against.
 *
 * Everything is per lane (`vec`: one cell per lane).  `model` is a
 * compile-time constant at every call, so each kernel is compiled for one law
 * without a branch.
 */
#ifndef RWALL_MATERIALS_H
#define RWALL_MATERIALS_H

#include "batch.h"

enum
{
  LINEAR_ELASTIC = 0,
  SAINT_VENANT_KIRCHHOFF = 1,
  NEO_HOOKEAN = 2
};

INLINE vec stress(int model, const vec L[9], double lambda, double mu, vec T[9])
{
  if (model == LINEAR_ELASTIC)
  {
    const vec tr = L[0] + L[4] + L[8];
    vec w = VZERO;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
      {
        const vec eps = 0.5 * (L[3 * i + j] + L[3 * j + i]);
        T[3 * i + j] = 2.0 * mu * eps;
        if (i == j)
          T[3 * i + j] += lambda * tr;
        w += 0.5 * T[3 * i + j] * eps;
      }
    return w;
  }
  vec F[9];
  for (int i = 0; i < 9; ++i)
    F[i] = i % 4 == 0 ? L[i] + 1.0 : L[i];
  if (model == SAINT_VENANT_KIRCHHOFF)
  {
    vec E[9], S[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
      {
        E[3 * i + j] = 0.5 * (F[i] * F[j] + F[3 + i] * F[3 + j] + F[6 + i] * F[6 + j]);
        if (i == j)
          E[3 * i + j] -= 0.5;
      }
    const vec tr = E[0] + E[4] + E[8];
    vec EE = VZERO;
    for (int i = 0; i < 9; ++i)
    {
      S[i] = 2.0 * mu * E[i];
      if (i % 4 == 0)
        S[i] += lambda * tr;
      EE += E[i] * E[i];
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        T[3 * i + j] = F[3 * i] * S[j] + F[3 * i + 1] * S[3 + j] + F[3 * i + 2] * S[6 + j];
    return 0.5 * lambda * tr * tr + mu * EE;
  }
  /* NEO_HOOKEAN (compressible): psi = mu/2 (F:F - 3) - mu ln J + lambda/2 (ln J)^2,
   * P = mu (F - F^-T) + lambda ln J F^-T, F^-T = cof(F) / J. */
  vec cof[9];
  cof[0] = F[4] * F[8] - F[5] * F[7];
  cof[1] = F[5] * F[6] - F[3] * F[8];
  cof[2] = F[3] * F[7] - F[4] * F[6];
  cof[3] = F[2] * F[7] - F[1] * F[8];
  cof[4] = F[0] * F[8] - F[2] * F[6];
  cof[5] = F[1] * F[6] - F[0] * F[7];
  cof[6] = F[1] * F[5] - F[2] * F[4];
  cof[7] = F[2] * F[3] - F[0] * F[5];
  cof[8] = F[0] * F[4] - F[1] * F[3];
  const vec J = F[0] * cof[0] + F[1] * cof[1] + F[2] * cof[2];
  const vec lnJ = vlog(J), inv_J = 1.0 / J;
  vec FF = VZERO;
  for (int i = 0; i < 9; ++i)
  {
    const vec FinvT = cof[i] * inv_J;
    T[i] = mu * (F[i] - FinvT) + lambda * lnJ * FinvT;
    FF += F[i] * F[i];
  }
  return 0.5 * mu * (FF - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
}

#endif
