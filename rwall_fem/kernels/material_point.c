/* The plastic update at a single material point (plasticity.h), for tests and
 * material drivers: one step of increment gradient dL (row-major 3 x 3) applied
 * to the stress sigma (xx, yy, zz, xy, yz, xz; Pa), the plastic strain and the
 * temperature (K), in place; returns the plastic dissipation density (J/m^3). */
#include "plasticity.h"

double plastic_point(const element_params *p, double sigma[6], double *eps_p, double *T,
                     const double dL[9])
{
  vec s[9], e = VZERO + *eps_p, t = VZERO + *T, g[9];
  s[0] = VZERO + sigma[0], s[4] = VZERO + sigma[1], s[8] = VZERO + sigma[2];
  s[1] = s[3] = VZERO + sigma[3];
  s[5] = s[7] = VZERO + sigma[4];
  s[2] = s[6] = VZERO + sigma[5];
  for (int i = 0; i < 9; ++i)
    g[i] = VZERO + dL[i];
  point_step done;
  const vec dissipation = plastic_update(p, s, &e, &t, g, &done);
  sigma[0] = s[0][0], sigma[1] = s[4][0], sigma[2] = s[8][0];
  sigma[3] = s[1][0], sigma[4] = s[5][0], sigma[5] = s[2][0];
  *eps_p = e[0];
  *T = t[0];
  return dissipation[0];
}
