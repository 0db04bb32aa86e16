/* Internal force of the Q1 (trilinear) hexahedron, full 2 x 2 x 2 Gauss integration.
 *
 * Reference cube [-1, 1]^3; node I of DOLFINx's numbering sits at
 * (xi_I, eta_I, zeta_I) = (2 (I & 1) - 1, 2 (I >> 1 & 1) - 1, 2 (I >> 2 & 1) - 1)
 * and N_I = (1 + xi_I xi)(1 + eta_I eta)(1 + zeta_I zeta) / 8.  At each of the
 * eight points (+-1/sqrt 3)^3 (weight 1): J = dx/dxi, grad N_I = J^-T dN_I/dxi,
 * f_I += |det J| T(grad u) grad N_I (materials.h).  This is the rule UFL uses
 * with quadrature degree 2 on hexahedra, which the tests compare against.
 */
#include "materials.h"

static const double SIGN[8][3] = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {-1, 1, 1},  {1, 1, 1}};

/* The nodal forces f[3 I + i] of a batch; returns the stored energy of each cell. */
INLINE vec hex8_cell(int model, const vec *restrict x, const vec *restrict u, vec *restrict f,
                     const element_params *p)
{
  const double a = 0.57735026918962576451; /* 1/sqrt(3) */
  vec energy = VZERO;
  for (int I = 0; I < 24; ++I)
    f[I] = VZERO;
  for (int q = 0; q < 8; ++q)
  {
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
    for (int i = 0; i < 9; ++i)
      inv[i] *= inv_det;
    vec g[8][3], L[9], T[9];
    for (int I = 0; I < 8; ++I)
      for (int j = 0; j < 3; ++j)
        g[I][j] = dN[I][0] * inv[j] + dN[I][1] * inv[3 + j] + dN[I][2] * inv[6 + j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
      {
        L[3 * i + j] = VZERO;
        for (int I = 0; I < 8; ++I)
          L[3 * i + j] += u[3 * I + i] * g[I][j];
      }
    const vec weight = vabs(det);
    energy += weight * stress(model, L, p->lmbda, p->mu, T);
    for (int I = 0; I < 8; ++I)
      for (int i = 0; i < 3; ++i)
        f[3 * I + i] += weight * (T[3 * i] * g[I][0] + T[3 * i + 1] * g[I][1]
                                  + T[3 * i + 2] * g[I][2]);
  }
  return energy;
}

INLINE void hex8_force(int model, int64_t num_cells, const int32_t *restrict cells,
                       const double *restrict X, const double *restrict u,
                       const element_params *p, double *restrict f, double *restrict energy)
{
  vec x[24], ue[24], fe[24];
  double total = 0.0;
  for (int64_t c0 = 0; c0 < num_cells; c0 += LANES)
  {
    const int nb = num_cells - c0 < LANES ? (int)(num_cells - c0) : LANES;
    gather(cells, 8, c0, nb, X, x);
    gather(cells, 8, c0, nb, u, ue);
    const vec w = hex8_cell(model, x, ue, fe, p);
    scatter_add(cells, 8, c0, nb, fe, f);
    total += lane_sum(w, nb);
  }
  energy[0] += total;
}

/* One function per law: f += f_int(u) on the cells (N), energy[0] += stored energy (J). */
void hex8_linear_elastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                         const element_params *p, double *f, double *energy)
{
  hex8_force(LINEAR_ELASTIC, n, cells, X, u, p, f, energy);
}

void hex8_saint_venant_kirchhoff(int64_t n, const int32_t *cells, const double *X,
                                 const double *u, const element_params *p, double *f,
                                 double *energy)
{
  hex8_force(SAINT_VENANT_KIRCHHOFF, n, cells, X, u, p, f, energy);
}

void hex8_neo_hookean(int64_t n, const int32_t *cells, const double *X, const double *u,
                      const element_params *p, double *f, double *energy)
{
  hex8_force(NEO_HOOKEAN, n, cells, X, u, p, f, energy);
}
