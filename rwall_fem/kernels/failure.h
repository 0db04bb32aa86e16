/* Failure criteria and erosion, in the kernels' pass over the cells (docs/theory.md,
 * "Failure and erosion").
 *
 * Damage D accumulates at each integration point of an elasto-plastic cell with the
 * plastic strain increments d of its steps, D += d / eps_f, with the failure strain
 * - FAILURE_PLASTIC_STRAIN: eps_f = p->failure_strain, constant (D = eps_p / eps_f);
 * - FAILURE_JOHNSON_COOK: eps_f = [D1 + D2 exp(D3 sigma*)] [1 + D4 ln max(rate / rate_0, 1)]
 *   [1 + D5 T*], sigma* the triaxiality (mean stress over von Mises stress) after the
 *   step's return, rate the equivalent strain rate of the step (that of the flow stress),
 *   T* the homologous temperature of the flow stress (its term only with heating).  A
 *   failure strain that is not positive fails the point at its first plastic increment.
 * A cell fails when D reaches 1 at one of its points (any of the eight of a 2 x 2 x 2
 * hexahedron).  With p->erode_step > 0 a cell also fails when its step estimate falls
 * below it, or when it is inverted (its step is nil): Radioss's /DT/BRICK/DEL.
 *
 * A failed cell is eroded in the pass that finds it: its forces of that pass are not
 * added, it is listed in p->eroded (step[11] counts them), and the internal energy it
 * leaves the books with is added to energy[3]: what it holds (elastic, plastic and
 * hourglass energy) less the work its last force would do over the step just taken,
 * 1/2 du . f with du = dt^{n-1/2} v^{n-1/2}, with which the balance of a linear force
 * closes exactly.  Its plastic and hourglass work so far (p->cell_work, kept per cell
 * while cells may erode) leave the live totals energy[2] and energy[1].  The caller
 * computes only the live cells from then on.
 */
#ifndef RWALL_FAILURE_H
#define RWALL_FAILURE_H

#include "plasticity.h"
#include "step.h"

enum
{
  FAILURE_NONE = 0,
  FAILURE_PLASTIC_STRAIN = 1,
  FAILURE_JOHNSON_COOK = 2
};

/* eps_f of a point after the step `done`, at temperature T (K). */
INLINE vec failure_strain(const element_params *p, const point_step *done, vec T)
{
  if (p->failure == FAILURE_PLASTIC_STRAIN)
    return VZERO + p->failure_strain;
  const double *D = p->damage_constants;
  vec strain = D[0] + D[1] * vexp(D[2] * done->triaxiality);
  if (D[3] != 0.0)
    strain *= 1.0 + D[3] * vlog(vmax(done->rate * (1.0 / p->damage_reference_rate), VZERO + 1.0));
  if (D[4] != 0.0 && p->thermal)
  {
    const vec star = vmin(vmax((T - p->room_temperature)
                                   * (1.0 / (p->melting_temperature - p->room_temperature)),
                               VZERO),
                          VZERO + 1.0);
    strain *= 1.0 + D[4] * star;
  }
  return vmax(strain, VZERO + 1e-300);
}

/* The damage of the batch's point at slot `slot` of the state (rows of `stride`) after the
 * step `done`, at temperature T (K): read, raised and stored only when the step flowed
 * plastically in some lane (the damage of a point changes only then, so that a cell
 * whose points do not flow, which cannot fail, costs nothing); else 0. */
INLINE vec accumulate_damage(const element_params *p, double *restrict state, int64_t stride,
                             const batch_t *b, int slot, const point_step *done, vec T)
{
  const ivec flowing = done->increment > 0.0;
  if (!p->failure || !any_lane(flowing))
    return VZERO;
  vec D = load_slot(state, stride, b, slot);
  D += vselect(flowing, done->increment / failure_strain(p, done, T), VZERO);
  store_slot(state, stride, b, slot, D);
  return D;
}

/* The lanes that fail in this pass: `damage` (the largest of the cell's points) reached 1,
 * or with p->erode_step the cell is inverted or its step estimate dte (s) is below it,
 * provided the energy it holds (J) is finite: an inverted neo-Hookean cell has none to
 * leave the books with, and stays inverted (the run stops). */
INLINE ivec failed_lanes(const element_params *p, vec damage, ivec inverted, vec dte, vec held)
{
  ivec failed = (ivec){0};
  if (!p->erode)
    return failed;
  if (p->failure)
    failed |= damage >= 1.0;
  if (p->erode_step > 0.0)
    failed |= (inverted | (dte < p->erode_step)) & (vabs(held) < INFINITY);
  return failed;
}

/* Add this step's work (J per lane) to the batch's cells' totals in row `row` of
 * p->cell_work (0: plastic, 1: hourglass), when some lane did any: a cell that does
 * nothing costs nothing. */
INLINE void track_work(const element_params *p, const batch_t *b, int row, vec work)
{
  const ivec done = work != 0.0;
  if (!p->cell_work || !any_lane(done))
    return;
  double *totals = p->cell_work + row * p->cell_stride;
  set_cell_values(totals, b, cell_values(totals, b) + work);
}

/* The work (J) of the batch's cells so far in row `row` of p->cell_work. */
INLINE vec work_so_far(const element_params *p, const batch_t *b, int row)
{
  return cell_values(p->cell_work + row * p->cell_stride, b);
}

/* The internal energy (J) a cell that holds `held` (J) leaves the books with when it is
 * eroded with nodal forces f[0 .. 3 npe) after the increment du (m). */
INLINE vec energy_left(vec held, const vec *restrict du, const vec *restrict f, int npe)
{
  vec work = VZERO;
  for (int i = 0; i < 3 * npe; ++i)
    work += du[i] * f[i];
  return held - 0.5 * work;
}

/* Erode the `failed` lanes of a batch: list their cells, book the energy `left` (J) of each
 * in energy[3], take their plastic and hourglass work so far (J; 0 where not accumulated)
 * out of energy[2] and energy[1], and zero their nodal forces f[0 .. 3 npe). */
INLINE void erode(const element_params *p, ivec failed, const batch_t *b, vec left,
                  vec plastic_total, vec hourglass_total, vec *restrict f, int npe,
                  double *energy, double *step)
{
  for (int k = 0; k < b->nb; ++k)
    if (failed[k])
    {
      p->eroded[(int64_t)step[11]++] = (int32_t)b->id[k];
      energy[3] += left[k];
      energy[2] -= plastic_total[k];
      energy[1] -= hourglass_total[k];
    }
  for (int i = 0; i < 3 * npe; ++i)
    f[i] = vselect(failed, VZERO, f[i]);
}

/* du = dt v of the batch's nodes (m): what an elastic cell needs to leave the books. */
INLINE void increments(const element_params *p, const int32_t *restrict cells, int npe,
                       const batch_t *b, vec *restrict du)
{
  gather(cells, npe, b, p->velocity, du);
  for (int i = 0; i < 3 * npe; ++i)
    du[i] *= p->dt;
}

/* The failure of a batch of elasto-plastic cells holding the elastic energy `elastic` (J)
 * after the plastic work `plastic` (and, with `hourglass` not NULL, the hourglass work) of
 * this step: the works are added to the cells' totals, and the failed lanes are eroded with
 * what they hold after the increment du (m) and their forces fe; returns those lanes. */
INLINE ivec erode_plastic(const element_params *p, const batch_t *b, vec damage, ivec inverted,
                          vec dte, vec elastic, vec plastic, const vec *hourglass,
                          const vec *restrict du, vec *restrict fe, int npe, double *energy,
                          double *step)
{
  const ivec failed = failed_lanes(p, damage, inverted, dte, elastic);
  track_work(p, b, 0, plastic);
  if (hourglass)
    track_work(p, b, 1, *hourglass);
  if (any_lane(failed))
  {
    const vec plastic_total = work_so_far(p, b, 0);
    const vec hourglass_total = hourglass ? work_so_far(p, b, 1) : VZERO;
    const vec held =
        hourglass ? elastic + plastic_total + hourglass_total : elastic + plastic_total;
    erode(p, failed, b, energy_left(held, du, fe, npe), plastic_total, hourglass_total, fe, npe,
          energy, step);
  }
  return failed;
}

/* The end of a batch: add its (live) cells' nodal forces fe into f, note the inverted
 * cells that did not erode, and the step estimates dte of the cells that are left
 * (step.h; u: NULL for an updated geometry x). */
INLINE void add_batch(const element_params *p, const int32_t *restrict cells, int npe,
                      const batch_t *b, ivec inverted, ivec failed, vec dte,
                      const vec *restrict x, const vec *restrict u, const vec *restrict fe,
                      double *restrict f, double *step)
{
  scatter_add(cells, npe, b, fe, f);
  note_inverted(inverted & ~failed, b, x, u, npe, step);
  if (p->estimate)
    note_steps(p, vselect(inverted | failed, VZERO + INFINITY, dte), b, cells, x, u, npe, step);
}

#endif
