/* The velocity boundary condition on its node set (rwall_fem/boundary.py), in one pass:
 *
 * boundary_velocity: set the accelerations a^n of the prescribed components so that
 *   v^{n+1/2} = v^{n-1/2} + dt^n a^n is the prescribed velocity, and note the reaction
 *   m (v_p - v^{n-1/2} - dt^n a^n) (N s), its power against v^{n-1/2} and its sum per
 *   component.
 * boundary_power: the reaction's power against the velocities the nodes have now.
 *
 * The arithmetic is that of the NumPy code these replace, operation for operation, so that
 * results stay the same to the bit; the powers are summed as NumPy sums them (numpy_sum of
 * wall.c; boundary.py sums more than one block of NumPy's buffer itself). The prescribed
 * places are distinct (a node set). */
#include <stdint.h>

#pragma GCC optimize("fp-contract=off")

double numpy_sum(int64_t n, const double *a);

/* power = reaction * v at the m places `flat` (N m/s). */
void boundary_power(int64_t m, const int64_t *restrict flat, const double *restrict reaction,
                    const double *restrict v, double *restrict power)
{
  for (int64_t i = 0; i < m; ++i)
    power[i] = reaction[i] * v[flat[i]];
}

/* For the n nodes `nodes` (rows of mass) with their `axes` prescribed components at the
 * places `flat` (n x axes indices into the flattened (nodes, 3) arrays v and a) prescribed
 * `target` (axes values, m/s): reaction and power (n x axes, N s and N m/s), sums (axes
 * values, N s, the reactions summed node after node: NumPy's order for 2 or 3 components,
 * not for 1); a^n of those places set.  works[1] = the power summed; with `settle`, first
 * works[0] = the power of the latest step's reaction (in `reaction`) at v now, summed. */
void boundary_velocity(int64_t n, int64_t axes, const int32_t *restrict nodes,
                       const int64_t *restrict flat, const double *restrict target, double dt_v,
                       const double *restrict mass, const double *restrict v,
                       double *restrict a, double *restrict reaction, double *restrict power,
                       double *restrict sums, int settle, double works[2])
{
  works[0] = 0.0;
  if (settle)
  {
    boundary_power(n * axes, flat, reaction, v, power);
    works[0] = numpy_sum(n * axes, power);
  }
  for (int64_t c = 0; c < axes; ++c)
    sums[c] = 0.0;
  for (int64_t i = 0; i < n; ++i)
  {
    const double m = mass[nodes[i]];
    for (int64_t c = 0; c < axes; ++c)
    {
      const int64_t at = axes * i + c, place = flat[at];
      const double v_old = v[place], change = target[c] - v_old;
      const double r = m * (change - dt_v * a[place]);
      a[place] = change / dt_v;
      reaction[at] = r;
      power[at] = r * v_old;
      sums[c] += r;
    }
  }
  works[1] = numpy_sum(n * axes, power);
}
