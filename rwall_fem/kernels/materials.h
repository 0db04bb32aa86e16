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

/* det(I + L): the volume ratio J at the point; J <= 0 is a cell turned inside out. */
INLINE vec volume_ratio(const vec L[9])
{
  const vec F0 = L[0] + 1.0, F4 = L[4] + 1.0, F8 = L[8] + 1.0;
  return F0 * (F4 * F8 - L[5] * L[7]) - L[1] * (L[3] * F8 - L[5] * L[6])
         + L[2] * (L[3] * L[7] - F4 * L[6]);
}

/* An upper bound on the largest eigenvalue of the symmetric 3 x 3 matrix G^T G (G
 * row-major), exact when two eigenvalues are equal: with m = tr/3 and the deviator D,
 * the largest is at most m + sqrt(2/3) |D|. */
INLINE vec gram_largest(const vec G[9])
{
  vec A[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      A[i][j] = G[i] * G[j] + G[3 + i] * G[3 + j] + G[6 + i] * G[6 + j];
  const vec m = (1.0 / 3.0) * (A[0][0] + A[1][1] + A[2][2]);
  const vec d0 = A[0][0] - m, d1 = A[1][1] - m, d2 = A[2][2] - m;
  const vec dd = d0 * d0 + d1 * d1 + d2 * d2
                 + 2.0 * (A[0][1] * A[0][1] + A[1][2] * A[1][2] + A[0][2] * A[0][2]);
  return m + vsqrt((2.0 / 3.0) * dd);
}

/* rho_0 c^2 (Pa): a bound on the largest eigenvalue of the acoustic tensor
 * A_ik = dP_iJ/dF_kL N_J N_L of the law at L = grad u, over unit directions N of the
 * reference configuration (docs/theory.md, "Stable time step"); lambda + 2 mu at rest.
 * Hooke: lambda + 2 mu.  Saint Venant-Kirchhoff: A = (N.S N) I + (lambda + mu) FN (x) FN
 * + mu |N|^2 F F^T, at most (lambda + 2 mu) max eig C + max(max eig S, 0).  Neo-Hookean:
 * A = mu I + (lambda + mu - lambda ln J) m (x) m, m = F^-T N, at most
 * mu + max(lambda + mu - lambda ln J, 0) max eig C^-1. */
INLINE vec wave_modulus(int model, const vec L[9], double lambda, double mu)
{
  if (model == LINEAR_ELASTIC)
    return VZERO + (lambda + 2.0 * mu);
  vec F[9];
  for (int i = 0; i < 9; ++i)
    F[i] = i % 4 == 0 ? L[i] + 1.0 : L[i];
  if (model == SAINT_VENANT_KIRCHHOFF)
  {
    const vec c = gram_largest(F);
    vec trC = VZERO;
    for (int i = 0; i < 9; ++i)
      trC += F[i] * F[i];
    const vec s = 0.5 * lambda * (trC - 3.0) + mu * (c - 1.0); /* max eig S */
    return (lambda + 2.0 * mu) * c + vmax(s, VZERO);
  }
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
  const vec inverse = gram_largest(cof) / (J * J); /* C^-1 = cof^T cof / J^2 */
  return mu + vmax(lambda + mu - lambda * vlog(J), VZERO) * inverse;
}

#endif
