/* Internal force of the C0 triangular shell of Belytschko, Stolarski and Carpenter (one
 * point, co-rotational frame), batched over cells like the quadrilateral (shell_quad.c).
 *
 * Each cycle the cell gets its local frame: e1 along the side x1 - x0, e3 along
 * (x1 - x0) x (x2 - x0), e2 = e3 x e1; the cell is flat in it (z_I = 0).  With the local
 * coordinates (x_I, y_I) about the centroid and 2A = x10 y20 - x20 y10, the linear shape
 * functions have the constant gradients
 *     b1 = (y12, y20, y01) / 2A,  b2 = (x21, x02, x10) / 2A.
 * Mindlin kinematics as the quadrilateral's: membrane d = (b1.vx, b2.vy, b2.vx + b1.vy)
 * (the constant-strain triangle), curvature k = (b1.ty, -b2.tx, b2.ty - b1.tx).
 * Transverse shear, tied along the sides (so that a constant curvature, w quadratic and
 * theta linear, gives no shear: no shear locking in bending): on the side from node I to
 * node J, of unit tangent s and length L,
 *     g_s = (vz_J - vz_I) / L + ((ty_I + ty_J) s_x - (tx_I + tx_J) s_y) / 2,
 * exact at the side's midpoint for those fields, and the cell's constant shear (xz, yz) is
 * the least-squares fit g = (S^T S)^-1 S^T g_s of the three sides' (S: rows s): exact for
 * every constant shear, zero for every rigid motion.  The resultants act back through the
 * transposed relations.  No hourglass control (the membrane and bending strains are
 * exact with one point).  Large rotations: the strain increments are dt times the rates in
 * the mid-step configuration x - dt v / 2 (a rigid motion of any size gives none) and the
 * forces are those of the current configuration, as the quadrilateral's; the resultants
 * are kept in the cell's frame.
 *
 * State, energies, failure and erosion as shell_quad.c; the stable step is L_c / c with
 * Radioss's L_c = 2 A / longest side, times p->calibration.
 */
#include "shell.h"

typedef struct
{
  vec e[3][3];          /* e1, e2, e3: their global components */
  vec x[3], y[3];       /* local coordinates of the nodes about the centroid, m */
  vec area;             /* A, m^2 */
  vec b1[3], b2[3];     /* dN_I/dx, dN_I/dy, 1/m */
  vec s[3][2], len[3];  /* sides I -> I + 1: unit tangents (local) and lengths, m */
  vec fit[2][3];        /* (S^T S)^-1 S^T: the constant shear of the sides' */
} tria_frame_t;

INLINE void tria_frame(const vec *restrict x, tria_frame_t *g)
{
  vec c[3], a1[3], a2[3];
  for (int i = 0; i < 3; ++i)
  {
    c[i] = (1.0 / 3.0) * (x[i] + x[3 + i] + x[6 + i]);
    a1[i] = x[3 + i] - x[i];
    a2[i] = x[6 + i] - x[i];
  }
  vec *e1 = g->e[0], *e2 = g->e[1], *e3 = g->e[2];
  cross(a1, a2, e3);
  const vec inv_n = 1.0 / vsqrt(dot3(e3, e3));
  const vec inv_a = 1.0 / vsqrt(dot3(a1, a1));
  for (int i = 0; i < 3; ++i)
  {
    e3[i] *= inv_n;
    e1[i] = a1[i] * inv_a;
  }
  cross(e3, e1, e2);
  for (int I = 0; I < 3; ++I)
  {
    const vec r[3] = {x[3 * I] - c[0], x[3 * I + 1] - c[1], x[3 * I + 2] - c[2]};
    g->x[I] = dot3(r, e1);
    g->y[I] = dot3(r, e2);
  }
  const vec *X = g->x, *Y = g->y;
  const vec two_area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  const vec inv = 1.0 / two_area;
  g->area = 0.5 * two_area;
  g->b1[0] = (Y[1] - Y[2]) * inv, g->b1[1] = (Y[2] - Y[0]) * inv, g->b1[2] = (Y[0] - Y[1]) * inv;
  g->b2[0] = (X[2] - X[1]) * inv, g->b2[1] = (X[0] - X[2]) * inv, g->b2[2] = (X[1] - X[0]) * inv;
  vec m00 = VZERO, m01 = VZERO, m11 = VZERO;
  for (int e = 0; e < 3; ++e)
  {
    const int J = (e + 1) % 3;
    const vec dx = X[J] - X[e], dy = Y[J] - Y[e];
    g->len[e] = vsqrt(dx * dx + dy * dy);
    const vec inv_l = 1.0 / g->len[e];
    g->s[e][0] = dx * inv_l;
    g->s[e][1] = dy * inv_l;
    m00 += g->s[e][0] * g->s[e][0];
    m01 += g->s[e][0] * g->s[e][1];
    m11 += g->s[e][1] * g->s[e][1];
  }
  const vec inv_det = 1.0 / (m00 * m11 - m01 * m01);
  for (int e = 0; e < 3; ++e)
  {
    g->fit[0][e] = (m11 * g->s[e][0] - m01 * g->s[e][1]) * inv_det;
    g->fit[1][e] = (m00 * g->s[e][1] - m01 * g->s[e][0]) * inv_det;
  }
}

INLINE void tria_to_local(const tria_frame_t *g, const vec *restrict a, vec out[3][3])
{
  for (int I = 0; I < 3; ++I)
    for (int k = 0; k < 3; ++k)
      out[I][k] = g->e[k][0] * a[3 * I] + g->e[k][1] * a[3 * I + 1] + g->e[k][2] * a[3 * I + 2];
}

INLINE void tria_strain_rates(const tria_frame_t *g, const vec vl[3][3], const vec wl[3][3],
                              vec d[3], vec k[3], vec gs[2])
{
  for (int i = 0; i < 3; ++i)
    d[i] = k[i] = VZERO;
  for (int I = 0; I < 3; ++I)
  {
    const vec b1 = g->b1[I], b2 = g->b2[I];
    d[0] += b1 * vl[I][0];
    d[1] += b2 * vl[I][1];
    d[2] += b2 * vl[I][0] + b1 * vl[I][1];
    k[0] += b1 * wl[I][1];
    k[1] -= b2 * wl[I][0];
    k[2] += b2 * wl[I][1] - b1 * wl[I][0];
  }
  gs[0] = gs[1] = VZERO;
  for (int e = 0; e < 3; ++e)
  {
    const int J = (e + 1) % 3;
    const vec side = (vl[J][2] - vl[e][2]) / g->len[e]
                     + 0.5 * ((wl[e][1] + wl[J][1]) * g->s[e][0]
                              - (wl[e][0] + wl[J][0]) * g->s[e][1]);
    gs[0] += g->fit[0][e] * side;
    gs[1] += g->fit[1][e] * side;
  }
}

/* The nodal forces and moments of the resultants, added to fe (global: forces at
 * fe[3 I + i], moments at fe[9 + 3 I + i]). */
INLINE void tria_resultant_forces(const tria_frame_t *g, const vec N[3], const vec M[3],
                                  const vec Q[2], vec *restrict fe)
{
  vec fl[3][3], ml[3][2];
  const vec A = g->area;
  for (int I = 0; I < 3; ++I)
  {
    const vec b1 = A * g->b1[I], b2 = A * g->b2[I];
    fl[I][0] = b1 * N[0] + b2 * N[2];
    fl[I][1] = b2 * N[1] + b1 * N[2];
    fl[I][2] = VZERO;
    ml[I][0] = -b2 * M[1] - b1 * M[2];
    ml[I][1] = b1 * M[0] + b2 * M[2];
  }
  for (int e = 0; e < 3; ++e)
  {
    const int J = (e + 1) % 3;
    const vec q = A * (g->fit[0][e] * Q[0] + g->fit[1][e] * Q[1]); /* the side's force */
    const vec qz = q / g->len[e];
    fl[J][2] += qz;
    fl[e][2] -= qz;
    const vec my = 0.5 * q * g->s[e][0], mx = -0.5 * q * g->s[e][1];
    ml[e][0] += mx, ml[J][0] += mx;
    ml[e][1] += my, ml[J][1] += my;
  }
  for (int I = 0; I < 3; ++I)
    for (int i = 0; i < 3; ++i)
    {
      fe[3 * I + i] += fl[I][0] * g->e[0][i] + fl[I][1] * g->e[1][i] + fl[I][2] * g->e[2][i];
      fe[9 + 3 * I + i] += ml[I][0] * g->e[0][i] + ml[I][1] * g->e[1][i];
    }
}

/* Radioss's characteristic length of a triangle: 2 A / longest side (m). */
INLINE vec tria_length(const tria_frame_t *g)
{
  return 2.0 * g->area / vmax(vmax(g->len[0], g->len[1]), g->len[2]);
}

INLINE void shell_tria(int plastic, int64_t num_cells, const int32_t *restrict cells,
                       const double *restrict X, const double *restrict u,
                       const double *restrict v, const double *restrict w,
                       const element_params *p, const shell_params *s, double *restrict state,
                       int64_t stride, double *restrict f, double *restrict m,
                       double *restrict energy, double *restrict step)
{
  const double dt = p->dt;
  double stored_total = 0.0, plastic_total = 0.0;
  for (int64_t k0 = 0; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    /* initialised: gather fills them lane by lane */
    vec Xe[9] = {VZERO}, ue[9] = {VZERO}, ve[9] = {VZERO}, we[9] = {VZERO}, x[9], xm[9], fe[18],
        du[18];
    shell_motion(cells, 3, &b, dt, X, u, v, w, Xe, ue, ve, we, x, xm, du, fe);
    const vec t = cell_values(s->thickness, &b);
    tria_frame_t g;
    tria_frame(xm, &g);
    vec vl[3][3], wl[3][3], d[3], k[3], gs[2];
    tria_to_local(&g, ve, vl);
    tria_to_local(&g, we, wl);
    tria_strain_rates(&g, vl, wl, d, k, gs);
    const vec mid_area = g.area;
    vec N[3], M[3], Q[2], elastic, dissipated, damage;
    const vec before =
        s->new_thickness ? shell_mean_stress(plastic, s, &b, state, stride, t) : VZERO;
    shell_update(plastic, p, s, &b, state, stride, t, d, k, gs, N, M, Q, &elastic, &dissipated,
                 &damage);
    if (s->new_thickness)
      shell_thickness_change(s, &b, t, d, before, (N[0] + N[1]) / t);
    tria_frame(x, &g);
    tria_resultant_forces(&g, N, M, Q, fe);
    elastic *= g.area;
    const vec plastic_work = dissipated * mid_area;
    const ivec inverted = ~(g.area > 0.0);
    vec dte = VZERO + INFINITY;
    if (p->estimate)
      dte = (p->calibration / s->bar_speed) * tria_length(&g);
    const ivec failed = erode_plastic(p, &b, damage, inverted, dte, elastic, plastic_work, NULL,
                                      du, fe, 6, energy, step);
    stored_total += lane_sum(vselect(failed, VZERO, elastic), b.nb);
    plastic_total += lane_sum(plastic_work, b.nb);
    scatter_add(cells, 3, &b, fe, f);
    scatter_add(cells, 3, &b, fe + 9, m);
    note_inverted(inverted & ~failed, &b, x, NULL, 3, step);
    if (p->estimate)
      note_steps(p, vselect(inverted | failed, VZERO + INFINITY, dte), &b, cells, x, NULL, 3, step);
  }
  energy[0] += stored_total;
  energy[2] += plastic_total;
}

/* f += internal forces (N), m += internal moments (N m) of the triangles `cells` (n x 3);
 * arguments as shell_quad_elastic's. */
void shell_tria_elastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                        const double *v, const double *w, const element_params *p,
                        const shell_params *s, double *state, int64_t stride, double *f,
                        double *m, double *energy, double *step)
{
  shell_tria(0, n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
}

void shell_tria_plastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                        const double *v, const double *w, const element_params *p,
                        const shell_params *s, double *state, int64_t stride, double *f,
                        double *m, double *energy, double *step)
{
  shell_tria(1, n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
}

/* The area (m^2) and characteristic length (m) of each triangle at x (s: unused, as for
 * the quadrilaterals' rules). */
void shell_tria_sizes(const shell_params *s, int64_t n, const int32_t *cells, const double *x,
                      double *area, double *length)
{
  vec xe[9] = {VZERO};
  for (int64_t k0 = 0; k0 < n; k0 += LANES)
  {
    const batch_t b = batch_at(NULL, k0, n);
    gather(cells, 3, &b, x, xe);
    tria_frame_t g;
    tria_frame(xe, &g);
    const vec l = tria_length(&g);
    for (int k = 0; k < b.nb; ++k)
    {
      area[k0 + k] = g.area[k];
      length[k0 + k] = l[k];
    }
  }
}
