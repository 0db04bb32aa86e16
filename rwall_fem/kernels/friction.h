/* Coulomb's law with Radioss's friction filter, shared by the rigid walls (wall.c: on
 * impulses) and the contact interfaces (contact.c: on forces):
 *
 *   F = alpha F_stick + (1 - alpha) F_kept    (the filter, when a kept value is given)
 *   |F| <= friction_limit                     (Coulomb: scaled back onto the cone)
 *
 * F_stick is what would stop the tangential motion (the wall's sticking impulse; the
 * contact's elastic trial force), F_kept the previous step's value, alpha in (0, 1].
 * Returns 1 when the law scaled F back (the node slips), else 0.  The arithmetic is the
 * one wall.c always had, operation for operation, so that wall results stay the same to
 * the bit.
 */
#ifndef RWALL_FRICTION_H
#define RWALL_FRICTION_H

#include "batch.h"

/* No fused multiply-add: the walls' results must round as they always did. */
#pragma GCC optimize("fp-contract=off")

INLINE double friction_norm3(const double x[3])
{
  return sqrt((x[0] * x[0] + x[1] * x[1]) + x[2] * x[2]);
}

/* Filter `stick` (3 values, in place) with `kept` (NULL: no filter) and bound it by
 * `limit` (>= 0, in the units of stick). */
INLINE int coulomb_law(double stick[3], const double *kept, double alpha, double limit)
{
  if (kept)
    for (int c = 0; c < 3; ++c)
      stick[c] = alpha * stick[c] + (1.0 - alpha) * kept[c];
  const double size = friction_norm3(stick);
  if (size > limit)
  {
    const double scale = limit / size;
    for (int c = 0; c < 3; ++c)
      stick[c] = stick[c] * scale;
    return 1;
  }
  return 0;
}

#endif
