/* The element time step and the inversion check, in the kernels' pass over the cells.
 *
 * Each cell estimates its stable step (docs/theory.md, "Stable time step"): its
 * characteristic length over its wave speed, dt_e = k L_e / c_e, with L_e = V / A_max for
 * hexahedra (the volume over the largest face area, LS-DYNA's and Radioss's length of
 * solids) and L_e = 3 V / A_max, the smallest altitude, for tetrahedra, and k =
 * p->calibration (the exact limit at rest over the estimate, at most 1); with the
 * viscous hourglass form at most the limit 2 / eta of its damped hourglass modes, which
 * the calibration (an eigenvalue of the stiffness alone) does not touch.  A kernel notes in `step`
 * (STEP_SLOTS values, accumulated over its calls):
 *   step[0]     the smallest dt_e of its cells (s; +inf: none estimated),
 *   step[1]     that cell (local index), step[2..4] its centroid (m, current position),
 *   step[5]     how many cells are inverted (a volume <= 0 at an integration point, or
 *               for hexahedra at a corner: hex8_corners_inverted),
 *   step[6]     the first of them, step[7..9] its centroid (m),
 *   step[10]    how many cells it listed in p->below (dt_e below p->step_floor),
 *   step[11]    how many cells it eroded, listed in p->eroded (failure.h).
 * A mass-scaled cell's dt_e is multiplied by its p->step_factor, sqrt(m / m_0).  An eroded
 * cell is neither estimated nor counted as inverted.
 */
#ifndef RWALL_STEP_H
#define RWALL_STEP_H

#include "batch.h"

#define STEP_SLOTS 12

/* Node pairs of the two diagonals of each face of a hexahedron (DOLFINx numbering). */
static const int HEX_FACE_DIAGONALS[6][4] = {{0, 6, 2, 4}, {1, 7, 3, 5}, {0, 5, 1, 4},
                                             {2, 7, 3, 6}, {0, 3, 1, 2}, {4, 7, 5, 6}};
/* The three nodes of each face of a tetrahedron. */
static const int TET_FACES[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};

/* (2 A_max)^2: the largest squared norm of d1 x d2 over the faces, d1 and d2 the
 * diagonals of a face of the hexahedra at x[3 I + i] (twice the area of a plane face; of
 * a warped face, twice its projected area). */
INLINE vec hex8_face_measure(const vec *restrict x)
{
  vec largest = VZERO;
  for (int f = 0; f < 6; ++f)
  {
    const int *d = HEX_FACE_DIAGONALS[f];
    vec d1[3], d2[3], n[3];
    for (int i = 0; i < 3; ++i)
    {
      d1[i] = x[3 * d[1] + i] - x[3 * d[0] + i];
      d2[i] = x[3 * d[3] + i] - x[3 * d[2] + i];
    }
    cross(d1, d2, n);
    largest = vmax(largest, dot3(n, n));
  }
  return largest;
}

/* (2 A_max)^2 of the tetrahedra at x[3 I + i]. */
INLINE vec tet4_face_measure(const vec *restrict x)
{
  vec largest = VZERO;
  for (int f = 0; f < 4; ++f)
  {
    const int *a = TET_FACES[f];
    vec d1[3], d2[3], n[3];
    for (int i = 0; i < 3; ++i)
    {
      d1[i] = x[3 * a[1] + i] - x[3 * a[0] + i];
      d2[i] = x[3 * a[2] + i] - x[3 * a[0] + i];
    }
    cross(d1, d2, n);
    largest = vmax(largest, dot3(n, n));
  }
  return largest;
}

/* The characteristic length (m) of cells of npe nodes at x, of volume `volume` (m^3). */
INLINE vec characteristic_length(int npe, const vec *restrict x, vec volume)
{
  if (npe == 8)
    return 2.0 * volume / vsqrt(hex8_face_measure(x));
  return 6.0 * volume / vsqrt(tet4_face_measure(x));
}

/* 2 / eta (s): the stable step of the hourglass modes of the viscous form, whose damping
 * rate is eta = kappa / m_node = 16 QM c V^(2/3) / V_0 (the hourglass vectors of a
 * parallelepiped have |gamma|^2 = 1/8, its nodes the mass rho V_0 / 8); an explicit
 * damper is stable for eta dt <= 2. */
INLINE vec viscous_hourglass_step(const element_params *p, vec volume, vec volume0)
{
  return volume0 / ((8.0 * p->hourglass_coefficient * p->wave_speed) * vcbrt(volume * volume));
}

/* The centroid (m) of lane k of cells of npe nodes at x (+ u, unless NULL). */
INLINE void centroid(const vec *restrict x, const vec *restrict u, int npe, int k, double *out)
{
  for (int i = 0; i < 3; ++i)
  {
    double sum = 0.0;
    for (int I = 0; I < npe; ++I)
      sum += x[3 * I + i][k] + (u ? u[3 * I + i][k] : 0.0);
    out[i] = sum / npe;
  }
}

/* Note the steps dt_e (s) of the batch's cells (node rows `cells`, npe a cell), at x (+ u):
 * the smallest so far, and when p->below is given the cells below p->step_floor, with
 * their steps before mass scaling in p->below_step.  NaN (a broken state, caught by the
 * run's guards) is never the smallest.  When p->nodal_stiffness is given, each cell with
 * a finite dt_e and m_c = p->nodal_mass of the cell (kg) not 0 (0: a cell at no contact
 * surface node) adds m_c / dt_e^2 (N/m) to each of its nodes: the element part of a
 * node's squared frequency bound, sum_c m_c (2 / dt_e)^2 / 4, that a nodal stable step
 * combines with the contact springs' (docs/theory.md, contact's "Stable step").  Mass
 * scaling multiplies m_c by s^2 and dt_e by s: the term is the same, so the step before
 * scaling serves. */
INLINE void note_steps(const element_params *p, vec dte, const batch_t *b,
                       const int32_t *restrict cells, const vec *restrict x,
                       const vec *restrict u, int npe, double *step)
{
  if (p->nodal_stiffness)
  {
    const vec term = cell_values(p->nodal_mass, b) / (dte * dte); /* dt_e inf: 0 */
    for (int k = 0; k < b->nb; ++k)
      if (term[k] > 0.0) /* not 0 (none to add) nor NaN */
      {
        const int32_t *cell = cells + b->id[k] * npe;
        for (int I = 0; I < npe; ++I)
          p->nodal_stiffness[cell[I]] += term[k];
      }
  }
  const vec scaled = p->step_factor ? dte * cell_values(p->step_factor, b) : dte;
  for (int k = 0; k < b->nb; ++k)
  {
    const double d = scaled[k];
    if (d < step[0])
    {
      step[0] = d;
      step[1] = (double)b->id[k];
      centroid(x, u, npe, k, step + 2);
    }
    if (p->below && d < p->step_floor)
    {
      const int64_t i = (int64_t)step[10]++;
      p->below[i] = (int32_t)b->id[k];
      p->below_step[i] = dte[k];
    }
  }
}

/* The lanes whose hexahedron (nodes at x, DOLFINx numbering, oriented so that the volume
 * at rest is positive) has a corner turned inside out: det J <= 0 at one of its eight
 * nodes.  At node I the trilinear map's Jacobian has the columns (x_high - x_low) / 2 of
 * the three edges through I, each taken along +xi_k (the nodes with bit k of their
 * number 1 and 0), so 8 det J_I = E_0 . (E_1 x E_2): twelve edge vectors, then eight
 * triple products, about 150 flops per cell.  A one-point cell's centre can keep a
 * positive volume while its corners invert (docs/theory.md, "Stable time step"). */
INLINE ivec hex8_corners_inverted(const vec *restrict x)
{
  vec edge[3][4][3]; /* edge[k][m]: along xi_k, the m-th of its four edges */
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 4; ++m)
    {
      /* the low node: bit k of its number 0, the other two bits those of m */
      const int low = ((m >> k) << (k + 1)) | (m & ((1 << k) - 1));
      const int high = low | (1 << k);
      for (int i = 0; i < 3; ++i)
        edge[k][m][i] = x[3 * high + i] - x[3 * low + i];
    }
  vec smallest = VZERO + INFINITY;
  for (int I = 0; I < 8; ++I)
  {
    /* the edge of each direction through node I: its number without bit k */
    const vec *e0 = edge[0][I >> 1], *e1 = edge[1][(I & 1) | ((I >> 2) << 1)],
              *e2 = edge[2][I & 3];
    vec n[3];
    cross(e1, e2, n);
    smallest = vmin(smallest, dot3(e0, n));
  }
  return smallest <= 0.0;
}

/* Count the cells of the batch that are inverted (`bad` lanes), and note the first. */
INLINE void note_inverted(ivec bad, const batch_t *b, const vec *restrict x,
                          const vec *restrict u, int npe, double *step)
{
  if (!any_lane(bad))
    return;
  for (int k = 0; k < b->nb; ++k)
    if (bad[k])
    {
      if (step[5] == 0.0)
      {
        step[6] = (double)b->id[k];
        centroid(x, u, npe, k, step + 7);
      }
      step[5] += 1.0;
    }
}

#endif
