/* Internal force of the Belytschko-Lin-Tsay quadrilateral shell (one in-plane point,
 * co-rotational frame, viscous hourglass control), batched over cells like the solids'.
 *
 * Notation (docs/theory.md, "Shell elements"): nodes I = 0..3 counter-clockwise (the caller
 * reorders DOLFINx's (0, 1, 3, 2)).  Each cycle the cell gets a local frame: e3 along
 * d02 x d13 (the diagonals), e1 along the projected xi direction x1 + x2 - x0 - x3,
 * e2 = e3 x e1.  The local coordinates (x_I, y_I, z_I) of the nodes about the centroid
 * have z_I = h (1, -1, 1, -1) (h = 0: a flat cell; h != 0: a warped one).  At the
 * centre, with 2A = x20 y31 - x31 y20 (A the projected area),
 *     b1 = (y13, y20, y31, y02) / 2A,  b2 = (x31, x02, x13, x20) / 2A   (dN_I/dx, dN_I/dy).
 * Mindlin kinematics: a fibre at height z moves with v + z (theta_y, -theta_x, 0), so the
 * velocity strains are, with v, theta the nodal velocities in the local frame,
 *     membrane   d = (b1.vx, b2.vy, b2.vx + b1.vy),
 *     curvature  k = (b1.ty, -b2.tx, b2.ty - b1.tx),
 *     shear      g = (b1.vz + mean ty, b2.vz - mean tx),
 * and the strain at height z is d + z k.  Stress resultants N (membrane), M (moments) and
 * Q (transverse shear, shear factor 5/6, elastic) act back through the transposed relations
 * (the power A (N.d + M.k + Q.g) equals f.v + m.theta).  The element has no drilling
 * stiffness (its moment about e3 is zero) unless s->kd > 0: drilling springs, see
 * quad_drill_update.
 *
 * Warping (s->warping, Belytschko-Wong-Chiang's correction by the rigid-body projection of
 * Belytschko and Leviathan): a rigid rotation (Ox, Oy) about the in-plane axes gives the
 * nodes of a warped cell the in-plane velocities (Oy z_I, -Ox z_I), which plain BT takes for
 * an hourglass motion (and whose forces are not in moment equilibrium).  The cell's rigid
 * rotation is the least-squares fit of all its nodal velocities about the centroid,
 *     Omega = J^-1 sum_I r_I x (v_I - mean v),  J = sum_I (|r_I|^2 I - r_I r_I^T),
 * and its part Omega x r_I is removed from the in-plane velocities before the strains and
 * hourglass rates are taken (the orthogonal projection: an in-plane hourglass motion is
 * not mistaken for a rotation, as it would be by a fit to vz alone); the in-plane forces
 * come back through the transpose, f_I -= mu x r_I with mu = J^-1 sum_I r_I x (fx, fy, 0)_I.
 * Any rigid motion then gives exactly zero strain rates, and the nodal forces and moments
 * of any stress are in equilibrium.
 *
 * Hourglass (viscous, Belytschko-Tsay): gamma_I = (G_I - (G.x) b1_I - (G.y) b2_I) / 4 with
 * G = (1, -1, 1, -1), orthogonal to every linear field; rates qm = gamma.v' (in-plane),
 * qw = gamma.vz, qr = gamma.theta; generalized forces C q with C = 4 rho c t sqrt(A) times
 * hm (membrane), hf (out of plane) and hr t^2 / 12 (rotations), c the bar speed.  hm = 0.01
 * is 1 % of the damping that is critical for a mode of frequency 2 c / sqrt(A) of a square
 * cell; their dissipation dt C q.q is the hourglass energy.  With s->hk > 0 elastic
 * hourglass forces are added, incremental in the cell's frame (state rows from
 * s->hourglass_slot): Q += k dt q with k = hk (2/3) E' t A |b|^2 (membrane; for a square,
 * hk (4/3) E' t, the normal-strain part of the fully integrated cell's in-plane bending),
 * 4 hk D A |b|^4 (out of plane) and hk (2/3) D A |b|^2 (rotations), E' = E / (1 - nu^2),
 * D = E' t^3 / 12, |b|^2 = sum b1^2 + b2^2; their work joins the hourglass energy.
 * With s->qeph_hourglass (Radioss's QEPH, Ishell 24, elasto-plastic cells) these elastic
 * hourglass forces yield as in OpenRadioss's CZFINTN1 (czfintn.F): see qeph_hourglass_yield.
 *
 * Rate form over the step dt = p->dt: the strain increments are dt times the velocity
 * strains of v, theta (v^{n-1/2}) in the mid-step configuration x - dt v / 2 (a rigid
 * motion gives none, whatever its rotation); the resultants, kept in the local frame, are
 * updated; their forces are those of the current configuration x = X + u.  The hourglass
 * rates and forces are those of the mid-step configuration, where a rigid motion has
 * exactly none (in the current one it would have rates of order dt |omega|^2 L, and a
 * spinning body would dissipate).
 *
 * Elastic cells keep the resultants (state rows 0..7: Nxx, Nyy, Nxy, Mxx, Myy, Mxy, Qx, Qy).
 * Elasto-plastic cells keep Qx, Qy (rows 0, 1) and, at each of s->points points through the
 * thickness (heights zeta_k t, weights w_k, shell.h), SHELL_POINT_SLOTS rows from
 * 2 + SHELL_POINT_SLOTS k: the stress (plane, exact J2 return of shell.h), plastic strain and
 * temperature; N = t sum w_k sigma_k, M = t^2 sum w_k zeta_k sigma_k; with a failure
 * criterion the damage of point k at row p->damage_slot + k.  A point whose damage reaches 1
 * carries no stress from then on (its elastic energy is booked as dissipated), and a cell
 * fails when the share s->fail_fraction of its points has failed; erosion as failure.h
 * (the nodal moments and rotations count in the energy the cell leaves with).  With
 * s->new_thickness (Radioss's Ithick = 1) the cell's thickness follows its membrane strain
 * increment after the update (shell.h, shell_thickness_change).
 *
 * energy[0] += stored elastic energy (J), energy[1] += hourglass dissipation of the step,
 * energy[2] += plastic dissipation of the step, energy[3] as failure.h.  The cell's stable
 * step is L_c / c with Radioss's L_c = max(A / longest diagonal, shortest side or diagonal)
 * in the current configuration (times p->calibration), noted in `step` (step.h); with
 * s->qeph_step, QEPH's L_c instead (quad_length_qeph).
 */
#include "shell.h"

static const double WARP_SIGN[4] = {1.0, -1.0, 1.0, -1.0};

typedef struct
{
  vec e[3][3];                 /* e1, e2, e3: their global components */
  vec x[4], y[4], z[4];        /* local coordinates of the nodes about the centroid, m */
  vec area;                    /* projected area A, m^2 */
  vec b1[4], b2[4];            /* dN_I/dx, dN_I/dy at the centre, 1/m */
} quad_frame_t;

/* The local frame and centre gradients of the cells at x[3 I + i]. */
INLINE void quad_frame(const vec *restrict x, quad_frame_t *g)
{
  vec c[3], d1[3], d2[3], t[3];
  for (int i = 0; i < 3; ++i)
  {
    c[i] = 0.25 * (x[i] + x[3 + i] + x[6 + i] + x[9 + i]);
    d1[i] = x[6 + i] - x[i];
    d2[i] = x[9 + i] - x[3 + i];
    t[i] = x[3 + i] + x[6 + i] - x[i] - x[9 + i];
  }
  vec *e1 = g->e[0], *e2 = g->e[1], *e3 = g->e[2];
  cross(d1, d2, e3);
  const vec inv_n = 1.0 / vsqrt(dot3(e3, e3));
  for (int i = 0; i < 3; ++i)
    e3[i] *= inv_n;
  const vec tn = dot3(t, e3);
  for (int i = 0; i < 3; ++i)
    t[i] -= tn * e3[i];
  const vec inv_t = 1.0 / vsqrt(dot3(t, t));
  for (int i = 0; i < 3; ++i)
    e1[i] = t[i] * inv_t;
  cross(e3, e1, e2);
  for (int I = 0; I < 4; ++I)
  {
    const vec r[3] = {x[3 * I] - c[0], x[3 * I + 1] - c[1], x[3 * I + 2] - c[2]};
    g->x[I] = dot3(r, e1);
    g->y[I] = dot3(r, e2);
    g->z[I] = dot3(r, e3);
  }
  const vec *X = g->x, *Y = g->y;
  const vec two_area = (X[2] - X[0]) * (Y[3] - Y[1]) - (X[3] - X[1]) * (Y[2] - Y[0]);
  const vec inv = 1.0 / two_area;
  g->area = 0.5 * two_area;
  g->b1[0] = (Y[1] - Y[3]) * inv, g->b1[1] = (Y[2] - Y[0]) * inv;
  g->b1[2] = (Y[3] - Y[1]) * inv, g->b1[3] = (Y[0] - Y[2]) * inv;
  g->b2[0] = (X[3] - X[1]) * inv, g->b2[1] = (X[0] - X[2]) * inv;
  g->b2[2] = (X[1] - X[3]) * inv, g->b2[3] = (X[2] - X[0]) * inv;
}

/* The local components out[I][k] of the nodal vectors a[3 I + i] (k < 3). */
INLINE void to_local(const quad_frame_t *g, const vec *restrict a, vec out[4][3])
{
  for (int I = 0; I < 4; ++I)
    for (int k = 0; k < 3; ++k)
      out[I][k] = g->e[k][0] * a[3 * I] + g->e[k][1] * a[3 * I + 1] + g->e[k][2] * a[3 * I + 2];
}

/* The inverse of the nodes' inertia tensor J = sum_I (|r_I|^2 I - r_I r_I^T) about the
 * centroid (local frame), row-major. */
INLINE void rigid_inverse(const quad_frame_t *g, vec Ji[9])
{
  vec J[9] = {VZERO, VZERO, VZERO, VZERO, VZERO, VZERO, VZERO, VZERO, VZERO};
  for (int I = 0; I < 4; ++I)
  {
    const vec r[3] = {g->x[I], g->y[I], g->z[I]};
    const vec rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        J[3 * i + j] += (i == j ? rr : VZERO) - r[i] * r[j];
  }
  const vec c0 = J[4] * J[8] - J[5] * J[7], c1 = J[5] * J[6] - J[3] * J[8];
  const vec c2 = J[3] * J[7] - J[4] * J[6];
  const vec inv = 1.0 / (J[0] * c0 + J[1] * c1 + J[2] * c2);
  Ji[0] = c0 * inv, Ji[3] = c1 * inv, Ji[6] = c2 * inv;
  Ji[1] = (J[2] * J[7] - J[1] * J[8]) * inv, Ji[4] = (J[0] * J[8] - J[2] * J[6]) * inv;
  Ji[7] = (J[1] * J[6] - J[0] * J[7]) * inv;
  Ji[2] = (J[1] * J[5] - J[2] * J[4]) * inv, Ji[5] = (J[2] * J[3] - J[0] * J[5]) * inv;
  Ji[8] = (J[0] * J[4] - J[1] * J[3]) * inv;
}

/* Remove the cell's rigid rotation, the least-squares fit Omega = J^-1 sum r_I x (v_I - mean v)
 * of all its nodal velocities, from the in-plane velocities (in place). */
INLINE void project_rigid(const quad_frame_t *g, const vec Ji[9], vec vl[4][3])
{
  vec mean[3], a[3] = {VZERO, VZERO, VZERO}, o[3];
  for (int i = 0; i < 3; ++i)
    mean[i] = 0.25 * (vl[0][i] + vl[1][i] + vl[2][i] + vl[3][i]);
  for (int I = 0; I < 4; ++I)
  {
    const vec r[3] = {g->x[I], g->y[I], g->z[I]};
    const vec d[3] = {vl[I][0] - mean[0], vl[I][1] - mean[1], vl[I][2] - mean[2]};
    vec c[3];
    cross(r, d, c);
    for (int i = 0; i < 3; ++i)
      a[i] += c[i];
  }
  for (int i = 0; i < 3; ++i)
    o[i] = Ji[3 * i] * a[0] + Ji[3 * i + 1] * a[1] + Ji[3 * i + 2] * a[2];
  for (int I = 0; I < 4; ++I)
  {
    vl[I][0] -= o[1] * g->z[I] - o[2] * g->y[I];
    vl[I][1] -= o[2] * g->x[I] - o[0] * g->z[I];
  }
}

/* The transpose of project_rigid on local nodal forces fl whose in-plane parts act on the
 * projected velocities (in place): fl_I -= mu x r_I, mu = J^-1 sum r_I x (fx_I, fy_I, 0). */
INLINE void project_rigid_forces(const quad_frame_t *g, const vec Ji[9], vec fl[4][3])
{
  vec M[3] = {VZERO, VZERO, VZERO}, mu[3];
  for (int I = 0; I < 4; ++I)
  {
    /* r x (fx, fy, 0) */
    M[0] -= g->z[I] * fl[I][1];
    M[1] += g->z[I] * fl[I][0];
    M[2] += g->x[I] * fl[I][1] - g->y[I] * fl[I][0];
  }
  for (int i = 0; i < 3; ++i)
    mu[i] = Ji[3 * i] * M[0] + Ji[3 * i + 1] * M[1] + Ji[3 * i + 2] * M[2];
  for (int I = 0; I < 4; ++I)
  {
    const vec r[3] = {g->x[I], g->y[I], g->z[I]};
    vec c[3];
    cross(mu, r, c);
    for (int i = 0; i < 3; ++i)
      fl[I][i] -= c[i];
  }
}

/* Membrane (xx, yy, gamma_xy), curvature and transverse shear velocity strains. */
INLINE void quad_strain_rates(const quad_frame_t *g, const vec vl[4][3], const vec wl[4][3],
                              vec d[3], vec k[3], vec gs[2])
{
  for (int i = 0; i < 3; ++i)
    d[i] = k[i] = VZERO;
  gs[0] = gs[1] = VZERO;
  vec tx = VZERO, ty = VZERO;
  for (int I = 0; I < 4; ++I)
  {
    const vec b1 = g->b1[I], b2 = g->b2[I];
    d[0] += b1 * vl[I][0];
    d[1] += b2 * vl[I][1];
    d[2] += b2 * vl[I][0] + b1 * vl[I][1];
    k[0] += b1 * wl[I][1];
    k[1] -= b2 * wl[I][0];
    k[2] += b2 * wl[I][1] - b1 * wl[I][0];
    gs[0] += b1 * vl[I][2];
    gs[1] += b2 * vl[I][2];
    tx += wl[I][0];
    ty += wl[I][1];
  }
  gs[0] += 0.25 * ty;
  gs[1] -= 0.25 * tx;
}

/* Add the local forces fl[I] and moments ml[I] (x, y) to the global fe[3 I + i] (forces)
 * and fe[12 + 3 I + i] (moments). */
INLINE void add_global(const quad_frame_t *g, const vec fl[4][3], const vec ml[4][2],
                       vec *restrict fe)
{
  for (int I = 0; I < 4; ++I)
    for (int i = 0; i < 3; ++i)
    {
      fe[3 * I + i] += fl[I][0] * g->e[0][i] + fl[I][1] * g->e[1][i] + fl[I][2] * g->e[2][i];
      fe[12 + 3 * I + i] += ml[I][0] * g->e[0][i] + ml[I][1] * g->e[1][i];
    }
}

/* The nodal forces and moments of the resultants N, M, Q on the cells of frame g, added
 * to fe (global). */
INLINE void quad_resultant_forces(const quad_frame_t *g, int warping, const vec Ji[9],
                                  const vec N[3], const vec M[3], const vec Q[2],
                                  vec *restrict fe)
{
  vec fl[4][3], ml[4][2];
  const vec A = g->area;
  for (int I = 0; I < 4; ++I)
  {
    const vec b1 = A * g->b1[I], b2 = A * g->b2[I];
    fl[I][0] = b1 * N[0] + b2 * N[2];
    fl[I][1] = b2 * N[1] + b1 * N[2];
    fl[I][2] = b1 * Q[0] + b2 * Q[1];
    ml[I][0] = -b2 * M[1] - b1 * M[2] - (0.25 * A) * Q[1];
    ml[I][1] = b1 * M[0] + b2 * M[2] + (0.25 * A) * Q[0];
  }
  if (warping)
    project_rigid_forces(g, Ji, fl);
  add_global(g, fl, ml, fe);
}

/* What QEPH's hourglass yield needs of a cell's material after its update of the step
 * (OpenRadioss's arguments of CZFINTN1 from MULAWC and M2CPLR): the mean and least over the
 * points through the thickness of E_t / E = H / (H + E) (1 at a point that did not flow this
 * step; ZCFAC), the mean flow stress (Pa; SIGY), and the mean stress N / t and M / t^2 (Pa;
 * GBUF%FOR, GBUF%MOM), both (xx, yy, xy).  As M2CPLR, the flow stress and its slope H are
 * those of the plastic strain e before the step, the slope at e + 1e-7 (finite at e = 0;
 * Johnson-Cook: with its thermal factor, not its rate factor). */
typedef struct
{
  vec mean_tangent, least_tangent, flow, membrane[3], bending[3];
} qeph_material_t;

/* qeph_material_t of a batch from its state rows after shell_update (plastic cells) and the
 * points' plastic strains before it, eps_before; N, M the new resultants. */
INLINE void qeph_material(const element_params *p, const shell_params *s, const batch_t *b,
                          const double *restrict state, int64_t stride, const vec eps_before[],
                          vec t, const vec N[3], const vec M[3], qeph_material_t *out)
{
  const double share = 1.0 / s->points;
  /* an uncapped linear law's slope is H at every strain: its E_t / E once */
  const int linear = p->hardening == HARDENING_LINEAR && !(p->max_flow_stress > 0.0);
  const double H = p->hardening_modulus, linear_tangent = H / (H + s->young);
  vec mean = VZERO, least = VZERO + 1.0, flow = VZERO;
  for (int pt = 0; pt < s->points; ++pt)
  {
    const int base = 2 + SHELL_POINT_SLOTS * pt;
    const vec e = load_slot(state, stride, b, base + 3);
    const vec T = p->thermal ? load_slot(state, stride, b, base + 4) : VZERO;
    const vec factor = flow_factor(p, VZERO, T);
    vec slope;
    flow += share * capped_flow_stress(p, eps_before[pt], factor, &slope);
    const ivec flowed = e > eps_before[pt];
    vec tangent = VZERO + linear_tangent;
    if (!linear)
    {
      if (any_lane(flowed)) /* the slope of the points that flowed only (1 elsewhere) */
        capped_flow_stress(p, eps_before[pt] + 1e-7, factor, &slope); /* M2CPLR's SMALL */
      tangent = slope / (slope + s->young);
    }
    tangent = vselect(flowed, tangent, VZERO + 1.0);
    mean += share * tangent;
    least = vmin(least, tangent);
  }
  out->mean_tangent = mean;
  out->least_tangent = least;
  out->flow = flow;
  for (int i = 0; i < 3; ++i)
  {
    out->membrane[i] = N[i] / t;
    out->bending[i] = M[i] / (t * t);
  }
}

/* sxx^2 + syy^2 - sxx syy + 3 sxy^2 (Pa^2). */
INLINE vec qeph_mises2(const vec s[3])
{
  return s[0] * s[0] + s[1] * s[1] - s[0] * s[1] + 3.0 * s[2] * s[2];
}

/* The yield norm of CZFINTN1 of two hourglass stress pairs a = (V1, V2), c = (V7, V8) (the
 * x and y modes), times COEF^2 = 0.85^2 (folded in by the caller): a.a + c.c terms and
 * their cross term. */
INLINE vec qeph_pair_norm(vec a1, vec a2, vec c1, vec c2)
{
  return a1 * a1 + a2 * a2 - a1 * a2 + c1 * c1 + c2 * c2 - c1 * c2
         + vabs(a1 * (2.0 * c1 - c2) + a2 * (2.0 * c2 - c1));
}

/* QEPH's yielding hourglass forces (OpenRadioss's CZFINTN1, czfintn.F, for a material with a
 * yield stress): the elastic increments dQ of the membrane (m = 0, 1) and bending (m = 3, 4)
 * hourglass forces of the step are scaled by 1 - EH1 and 1 - EH2 (the out-of-plane mode,
 * m = 2, and the viscous forces never yield).  The cell yields when one of its points
 * flowed this step (E_t / E < 1), or, all elastic, when
 *     SVM = S0 + 25 M0 > sigma_y^2,
 *     S0 = |N / t|_VM^2 + 0.85^2 h(V_m),   M0 = |M / t^2|_VM^2 + (0.85 t / 16)^2 h(V_b),
 * h as qeph_pair_norm, V the hourglass stresses (below); then
 *     EH1 = max(0.999 min(S0 / sigma_y^2, 1), 1 - mean E_t / E)   (S0 = 0 if a point flowed),
 *     EH2 = max(0.999, 1 - least E_t / E),
 * each 0 if the work of the old forces on the step's increments (membrane, bending) is
 * negative (unloading).  With the deck's hardening H = 300 MPa, E_t / E = H / (H + E) =
 * 0.0014: 99.86 % of a flowing cell's membrane increment, and 99.9 % of its bending one,
 * are taken back.  The hourglass stresses V are those of a square cell of side sqrt(A)
 * (Radioss's VGLAS): E' 2 / sqrt(A) times the elastic hourglass displacement Q / k of the
 * new forces (the stress at the cell's edge of the in-plane or out-of-plane bending that
 * the mode is), the x mode (V, -nu V), the y mode (-nu V, V); the bending modes are the
 * rotations about y and minus those about x (CZDEF's DHG3, DHG4).  old, dq, k: the forces
 * before the step, the increments dt q and the stiffnesses of quad_hourglass; dQ in/out. */
/* The shares EH1, EH2 of the step's membrane and bending hourglass stress increments that
 * CZFINTN1 takes back (qeph_hourglass_yield's rule) from the pair norms hm, hb of the new
 * hourglass stresses (qeph_pair_norm, Pa^2, without COEF) and whether the old forces work
 * positively on the increments (loading; unloading is elastic). */
INLINE void qeph_yield_factors(const qeph_material_t *mat, vec t, vec hm, vec hb,
                               ivec loading_m, ivec loading_b, vec *eh1, vec *eh2)
{
  const vec cm = (0.85 / 16.0) * t;
  const vec flowing = VZERO + (1.0 - mat->least_tangent);
  const vec yield2 = mat->flow * mat->flow;
  const ivec elastic = flowing <= 0.0;
  const vec S0 = vselect(elastic, qeph_mises2(mat->membrane) + (0.85 * 0.85) * hm, VZERO);
  const vec M0 = qeph_mises2(mat->bending) + cm * cm * hb;
  const ivec yields = ~elastic | (S0 + 25.0 * M0 > yield2);
  const vec e1 = vmax(0.999 * vmin(S0 / vmax(yield2, VZERO + 1e-18), VZERO + 1.0),
                      1.0 - mat->mean_tangent);
  const vec e2 = vmax(VZERO + 0.999, flowing);
  *eh1 = vselect(yields & loading_m, e1, VZERO);
  *eh2 = vselect(yields & loading_b, e2, VZERO);
}

INLINE void qeph_hourglass_yield(const shell_params *s, const qeph_material_t *mat, vec area,
                                 vec t, const vec old[5], const vec dq[5], const vec k[5],
                                 vec dQ[5])
{
  const double Ep = s->young / (1.0 - s->poisson * s->poisson), nu = s->poisson;
  const vec scale = (2.0 * Ep) / vsqrt(area);
  vec V[5];
  for (int m = 0; m < 5; ++m)
    V[m] = scale * (old[m] + dQ[m]) / k[m];
  vec eh1, eh2;
  qeph_yield_factors(mat, t, qeph_pair_norm(V[0], -nu * V[0], -nu * V[1], V[1]),
                     qeph_pair_norm(V[4], -nu * V[4], nu * V[3], -V[3]),
                     old[0] * dq[0] + old[1] * dq[1] >= 0.0,
                     old[3] * dq[3] + old[4] * dq[4] >= 0.0, &eh1, &eh2);
  dQ[0] *= 1.0 - eh1;
  dQ[1] *= 1.0 - eh1;
  dQ[3] *= 1.0 - eh2;
  dQ[4] *= 1.0 - eh2;
}

/* The constants of quad_hourglass_qeph, taken once per kernel call: E' = E / (1 - nu^2) (Pa),
 * nu, C = G k / 64 (Pa) and the square roots of its viscosity, sqrt(E'), sqrt(nu E') and
 * sqrt(G k / 12) (Pa^1/2). */
typedef struct
{
  double Ep, nu, C, root_Ep, root_nu_Ep, root_shear;
} qeph_constants_t;

INLINE qeph_constants_t qeph_constants(const shell_params *s)
{
  qeph_constants_t c;
  c.Ep = s->young / (1.0 - s->poisson * s->poisson), c.nu = s->poisson;
  c.C = 0.5 * s->young / (1.0 + s->poisson) * s->shear_factor / 64.0;
  c.root_Ep = sqrt(c.Ep), c.root_nu_Ep = sqrt(c.nu * c.Ep);
  c.root_shear = sqrt(64.0 * c.C / 12.0);
  return c;
}

/* QEPH's physical hourglass stiffness (Radioss's Ishell 24, OpenRadioss's CZDEF and
 * CZFINTN1, czdef.F and czfintn.F; s->qeph_physical).  With the nodes' mid-points about the
 * centroid MX13 = (x0 + x2) / 2, MX23 = (x1 + x2) / 2, MX34 = (x2 + x3) / 2 (MY.. alike),
 * h = (1, -1, 1, -1), and the hourglass increments of the step
 *     d1 = dt gamma.vx, d2 = dt gamma.vy            (membrane: CZDEF's VHG1, VHG2)
 *     d3 = dt gamma.theta_y, d4 = -dt gamma.theta_x  (bending: VHG3, VHG4)
 *     d5 = 4 dt (h.vz - MY13 S(tx) + MY23 S23(tx) - MX23 S23(ty) + MX13 S(ty)),
 *     d6 = the same with MY34, MX34 and S34         (transverse shear: VHG5, VHG6),
 * S the nodes' sum, S23 with the signs (1, 1, -1, -1), S34 with (1, -1, -1, 1) (d5 and d6
 * vanish in any rigid motion and in the constant-twist mode w = a x y), the twelve
 * hourglass stresses V (state rows s->hourglass_slot..+11, Pa) take the increments, with
 * HXX = 4 MY34 / A, HYY = 4 MX34 / A, HXX_K = 4 MY23 / A, HYY_K = 4 MX23 / A, E' = E / (1 - nu^2),
 *     V1 += E' (HXX d1 - nu HYY d2),   V2 += E' (HYY d2 - nu HXX d1),
 *     V7 += E' (HXX_K d1 - nu HYY_K d2), V8 += E' (HYY_K d2 - nu HXX_K d1),
 * V3, V4, V9, V10 the same of d3, d4, and with C = G k / 64 (k the shear factor)
 *     V5 += C HXX d5, V6 += C HYY d5, V11 += C HXX_K d6, V12 += C HYY_K d6,
 * (CZFINTN1's FAC1 = 1), the membrane and bending increments yielding as
 * qeph_yield_factors with the norms of (V1, V2 | V7, V8) and (V3, V4 | V9, V10).  Their
 * generalized forces, conjugate to d1 .. d6 (N, N m, N / m),
 *     F1 = 4/3 t (MY34 V1 + MY23 V7),   F2 = 4/3 t (MX23 V8 + MX34 V2),
 *     F3 = 4/3 t^3/12 (MY34 V3 + MY23 V9),  F4 = 4/3 t^3/12 (MX23 V10 + MX34 V4),
 *     F5 = t/3 (MY34 V5 + MX34 V6),   F6 = t/3 (MY23 V11 + MX23 V12),
 * act on the nodes through the transposed rates (as CZFINTN1's VF, VM).  On an a x c
 * rectangle: F1 = 4/3 E' t (c / a) d1, the exact energy of the mode vx = x y / ... in plane
 * stress (tests/shells/test_qeph_hourglass.py).  Adds F1 to Q[0], F2 to Q[1], -F4 to Q[3],
 * F3 to Q[4] (the gamma modes) and the shear's nodal forces and moments to fz, ml; returns
 * the work of the step, sum (F_old + F_new) d / 2 (J). */
INLINE vec quad_hourglass_qeph(const quad_frame_t *g, const shell_params *s,
                               const qeph_constants_t *qc, double density,
                               double dt, vec t, const vec q[5], const vec vl[4][3], const vec wl[4][3],
                               double *restrict state, int64_t stride, const batch_t *b,
                               const qeph_material_t *yielding, vec Q[5], vec fz[4],
                               vec ml[4][2])
{
  static const double S23[4] = {1.0, 1.0, -1.0, -1.0}, S34[4] = {1.0, -1.0, -1.0, 1.0};
  const vec *X = g->x, *Y = g->y;
  const vec mx13 = 0.5 * (X[0] + X[2]), mx23 = 0.5 * (X[1] + X[2]), mx34 = 0.5 * (X[2] + X[3]);
  const vec my13 = 0.5 * (Y[0] + Y[2]), my23 = 0.5 * (Y[1] + Y[2]), my34 = 0.5 * (Y[2] + Y[3]);
  vec hz = VZERO, sx = VZERO, sy = VZERO, s23x = VZERO, s23y = VZERO, s34x = VZERO,
      s34y = VZERO;
  for (int I = 0; I < 4; ++I)
  {
    hz += WARP_SIGN[I] * vl[I][2];
    sx += wl[I][0], sy += wl[I][1];
    s23x += S23[I] * wl[I][0], s23y += S23[I] * wl[I][1];
    s34x += S34[I] * wl[I][0], s34y += S34[I] * wl[I][1];
  }
  const vec r[6] = {q[0], q[1], q[4], -q[3],
                    4.0 * (hz - my13 * sx + my23 * s23x - mx23 * s23y + mx13 * sy),
                    4.0 * (hz - my13 * sx + my34 * s34x - mx34 * s34y + mx13 * sy)};
  vec d[6];
  for (int m = 0; m < 6; ++m)
    d[m] = dt * r[m];
  const vec inv4 = 4.0 / g->area;
  const vec hxx = inv4 * my34, hyy = inv4 * mx34, hxxk = inv4 * my23, hyyk = inv4 * mx23;
  const double Ep = qc->Ep, nu = qc->nu, C = qc->C;
  vec V[12], dV[12];
  for (int m = 0; m < 12; ++m)
    V[m] = load_slot(state, stride, b, s->hourglass_slot + m);
  /* V1, V2, V7, V8 (rows 0, 1, 6, 7) of d1, d2; V3, V4, V9, V10 (2, 3, 8, 9) of d3, d4 */
  for (int j = 0; j < 2; ++j)
  {
    const vec da = d[2 * j], db = d[2 * j + 1];
    dV[2 * j] = Ep * (hxx * da - nu * hyy * db);
    dV[2 * j + 1] = Ep * (hyy * db - nu * hxx * da);
    dV[6 + 2 * j] = Ep * (hxxk * da - nu * hyyk * db);
    dV[7 + 2 * j] = Ep * (hyyk * db - nu * hxxk * da);
  }
  dV[4] = C * hxx * d[4], dV[5] = C * hyy * d[4];
  dV[10] = C * hxxk * d[5], dV[11] = C * hyyk * d[5];
  const vec c43 = (4.0 / 3.0) * t, c43b = c43 * (t * t / 12.0), c13 = t / 3.0;
  vec F_old[6];
  F_old[0] = c43 * (my34 * V[0] + my23 * V[6]);
  F_old[1] = c43 * (mx23 * V[7] + mx34 * V[1]);
  F_old[2] = c43b * (my34 * V[2] + my23 * V[8]);
  F_old[3] = c43b * (mx23 * V[9] + mx34 * V[3]);
  F_old[4] = c13 * (my34 * V[4] + mx34 * V[5]);
  F_old[5] = c13 * (my23 * V[10] + mx23 * V[11]);
  for (int m = 0; m < 12; ++m)
    V[m] += dV[m];
  if (yielding)
  {
    vec eh1, eh2;
    qeph_yield_factors(yielding, t, qeph_pair_norm(V[0], V[1], V[6], V[7]),
                       qeph_pair_norm(V[2], V[3], V[8], V[9]),
                       F_old[0] * d[0] + F_old[1] * d[1] >= 0.0,
                       F_old[2] * d[2] + F_old[3] * d[3] >= 0.0, &eh1, &eh2);
    static const int MEMBRANE[4] = {0, 1, 6, 7}, BENDING[4] = {2, 3, 8, 9};
    for (int j = 0; j < 4; ++j)
    {
      V[MEMBRANE[j]] -= eh1 * dV[MEMBRANE[j]];
      V[BENDING[j]] -= eh2 * dV[BENDING[j]];
    }
  }
  for (int m = 0; m < 12; ++m)
    store_slot(state, stride, b, s->hourglass_slot + m, V[m]);
  vec F[6];
  F[0] = c43 * (my34 * V[0] + my23 * V[6]);
  F[1] = c43 * (mx23 * V[7] + mx34 * V[1]);
  F[2] = c43b * (my34 * V[2] + my23 * V[8]);
  F[3] = c43b * (mx23 * V[9] + mx34 * V[3]);
  F[4] = c13 * (my34 * V[4] + mx34 * V[5]);
  F[5] = c13 * (my23 * V[10] + mx23 * V[11]);
  vec work = VZERO;
  for (int m = 0; m < 6; ++m)
    work += 0.5 * (F_old[m] + F[m]) * d[m];
  /* QEPH's viscous hourglass forces (CZFINTN1's SS1_V .. SC6_V, booked in its hourglass
   * energy EVIS): with mu = dn sqrt(rho A) / A and the rates r = d / dt,
   *   F1 += t mu (sqrt(E') 16/3 (MY34^2 + MY23^2) r1 - sqrt(nu E') 16/3 (MY34 MX34 + MY23 MX23) r2),
   * F2 alike, F3, F4 the same of r3, r4 times t^2 sqrt(12) / 12, and
   *   F5 += t mu sqrt(G k / 12) (MY34^2 + MX34^2) r5 / 4, F6 with MY23, MX23 */
  const vec mu = s->qeph_dn * vsqrt(density * g->area) / g->area;
  const vec vxx = (16.0 / 3.0) * (my34 * my34 + my23 * my23),
            vyy = (16.0 / 3.0) * (mx23 * mx23 + mx34 * mx34),
            vxy = (-16.0 / 3.0) * (my34 * mx34 + my23 * mx23);
  const vec cxx = (qc->root_Ep * mu) * vxx, cyy = (qc->root_Ep * mu) * vyy,
            cxy = (qc->root_nu_Ep * mu) * vxy;
  const vec gz = (qc->root_shear * mu) * t; /* sqrt(G k / 12) HVL t / A */
  vec Fv[6];
  Fv[0] = t * (cxx * r[0] + cxy * r[1]);
  Fv[1] = t * (cyy * r[1] + cxy * r[0]);
  Fv[2] = (t * t * t / 12.0 * sqrt(12.0)) * (cxx * r[2] + cxy * r[3]);
  Fv[3] = (t * t * t / 12.0 * sqrt(12.0)) * (cyy * r[3] + cxy * r[2]);
  Fv[4] = 0.25 * gz * (my34 * my34 + mx34 * mx34) * r[4];
  Fv[5] = 0.25 * gz * (mx23 * mx23 + my23 * my23) * r[5];
  for (int m = 0; m < 6; ++m)
  {
    work += Fv[m] * d[m];
    F[m] += Fv[m];
  }
  Q[0] += F[0];
  Q[1] += F[1];
  Q[3] -= F[3];
  Q[4] += F[2];
  /* the transverse shear's: d(d5)/dt over the nodes' vz, theta_x, theta_y, times F5 */
  const vec f5 = 4.0 * F[4], f6 = 4.0 * F[5];
  for (int I = 0; I < 4; ++I)
  {
    fz[I] = WARP_SIGN[I] * (f5 + f6);
    ml[I][0] = f5 * (S23[I] * my23 - my13) + f6 * (S34[I] * my34 - my13);
    ml[I][1] = f5 * (mx13 - S23[I] * mx23) + f6 * (mx13 - S34[I] * mx34);
  }
  return work;
}

/* The viscous hourglass forces of the cells of frame g (added to fe, global) from the local
 * velocities vl (projected when warping) and angular velocities wl; returns their power, W. */
INLINE vec quad_hourglass(const quad_frame_t *g, const shell_params *s,
                          const qeph_constants_t *qc, double density,
                          double dt, vec thickness, int warping, const vec Ji[9],
                          const vec vl[4][3],
                          const vec wl[4][3], double *restrict state, int64_t stride,
                          const batch_t *b, const qeph_material_t *yielding, vec *restrict fe)
{
  vec gx = VZERO, gy = VZERO;
  for (int I = 0; I < 4; ++I)
  {
    gx += WARP_SIGN[I] * g->x[I];
    gy += WARP_SIGN[I] * g->y[I];
  }
  vec gamma[4], q[5] = {VZERO, VZERO, VZERO, VZERO, VZERO};
  for (int I = 0; I < 4; ++I)
  {
    gamma[I] = 0.25 * (WARP_SIGN[I] - gx * g->b1[I] - gy * g->b2[I]);
    for (int k = 0; k < 3; ++k)
      q[k] += gamma[I] * vl[I][k];
    q[3] += gamma[I] * wl[I][0];
    q[4] += gamma[I] * wl[I][1];
  }
  vec Q[5] = {VZERO, VZERO, VZERO, VZERO, VZERO}, work = VZERO;
  if (s->hm != 0.0 || s->hf != 0.0 || s->hr != 0.0) /* QEPH's have none (a square root) */
  {
    const vec C = (4.0 * density * s->bar_speed) * thickness * vsqrt(g->area);
    const vec Cm = s->hm * C, Cf = s->hf * C, Cr = (s->hr / 12.0) * C * thickness * thickness;
    Q[0] = Cm * q[0], Q[1] = Cm * q[1], Q[2] = Cf * q[2], Q[3] = Cr * q[3], Q[4] = Cr * q[4];
    for (int k = 0; k < 5; ++k)
      work += dt * Q[k] * q[k];
  }
  vec fz[4] = {VZERO, VZERO, VZERO, VZERO}, ms[4][2] = {{VZERO, VZERO}, {VZERO, VZERO},
                                                        {VZERO, VZERO}, {VZERO, VZERO}};
  if (s->qeph_physical)
    work += quad_hourglass_qeph(g, s, qc, density, dt, thickness, q, vl, wl, state, stride, b,
                                yielding, Q, fz, ms);
  else if (s->hk > 0.0)
  {
    /* elastic hourglass forces, incremental in the cell's frame: dQ = k dt q */
    vec bb = VZERO;
    for (int I = 0; I < 4; ++I)
      bb += g->b1[I] * g->b1[I] + g->b2[I] * g->b2[I];
    const double Ep = s->young / (1.0 - s->poisson * s->poisson);
    const vec bending = (Ep / 12.0) * thickness * thickness * thickness;
    const vec km = (s->hk * 2.0 / 3.0 * Ep) * thickness * g->area * bb;
    const vec kw = (4.0 * s->hk) * bending * g->area * bb * bb;
    const vec kr = (s->hk * 2.0 / 3.0) * bending * g->area * bb;
    const vec k[5] = {km, km, kw, kr, kr};
    vec old[5], dq[5], dQ[5];
    for (int m = 0; m < 5; ++m)
    {
      old[m] = load_slot(state, stride, b, s->hourglass_slot + m);
      dq[m] = dt * q[m];
      dQ[m] = k[m] * dq[m];
    }
    if (yielding)
      qeph_hourglass_yield(s, yielding, g->area, thickness, old, dq, k, dQ);
    for (int m = 0; m < 5; ++m)
    {
      store_slot(state, stride, b, s->hourglass_slot + m, old[m] + dQ[m]);
      work += (old[m] + 0.5 * dQ[m]) * dq[m];
      Q[m] += old[m] + dQ[m];
    }
  }
  vec fl[4][3], ml[4][2];
  for (int I = 0; I < 4; ++I)
  {
    for (int k = 0; k < 3; ++k)
      fl[I][k] = gamma[I] * Q[k];
    fl[I][2] += fz[I];
    ml[I][0] = gamma[I] * Q[3] + ms[I][0];
    ml[I][1] = gamma[I] * Q[4] + ms[I][1];
  }
  if (warping)
    project_rigid_forces(g, Ji, fl);
  add_global(g, fl, ml, fe);
  return work;
}

/* Drilling (s->kd > 0): the nodes' rotation rates about e3 less the cell's in-plane spin at
 * the centre, spin = (b1.vy - b2.vx) / 2 of the local velocities vl (not projected: a rigid
 * motion has exactly spin = its rotation rate about e3), are resisted by elastic springs,
 * incremental in the state rows s->drill_slot + I: mz_I += kd G t A dt (wz_I - spin).
 * Writes mz (N m) and returns their stored energy sum mz_I^2 / (2 k) (J). */
INLINE vec quad_drill_update(const quad_frame_t *g, const shell_params *s, double dt,
                             vec thickness, const vec vl[4][3], const vec wl[4][3],
                             double *restrict state, int64_t stride, const batch_t *b,
                             vec mz[4])
{
  vec spin = VZERO;
  for (int I = 0; I < 4; ++I)
    spin += g->b1[I] * vl[I][1] - g->b2[I] * vl[I][0];
  spin *= 0.5;
  const double G = 0.5 * s->young / (1.0 + s->poisson);
  const vec k = (s->kd * G) * thickness * g->area;
  vec energy = VZERO;
  for (int I = 0; I < 4; ++I)
  {
    mz[I] = load_slot(state, stride, b, s->drill_slot + I) + k * dt * (wl[I][2] - spin);
    store_slot(state, stride, b, s->drill_slot + I, mz[I]);
    energy += 0.5 * mz[I] * mz[I] / k;
  }
  return energy;
}

/* The nodal moments mz (about e3) of the drilling springs and the in-plane forces of their
 * spin term (the transpose: f_I = (sum mz) (b2_I, -b1_I) / 2), added to fe (global). */
INLINE void quad_drill_forces(const quad_frame_t *g, const vec mz[4], vec *restrict fe)
{
  const vec half = 0.5 * (mz[0] + mz[1] + mz[2] + mz[3]);
  for (int I = 0; I < 4; ++I)
  {
    const vec fx = half * g->b2[I], fy = -half * g->b1[I];
    for (int i = 0; i < 3; ++i)
    {
      fe[3 * I + i] += fx * g->e[0][i] + fy * g->e[1][i];
      fe[12 + 3 * I + i] += mz[I] * g->e[2][i];
    }
  }
}

/* QEPH's characteristic length (m) of the cells of frame g (OpenRadioss's czcorc.F,
 * CZCORC1, for Ishell 24), times sqrt(1 + dn^2) - dn of its numerical damping dn (cndt3.F):
 * L_c = A / (F (5/4 + h) max(|x13|^2, |x24|^2))^(1/2), with x13, x24 the half diagonals,
 * F = 2 (1 + min(1/2, (max(C1, C2) / min(C1, C2) - 1) / 4)) (0.78 + 0.22 f^3),
 * f = 3.413 max(0, 4 A / (C1 C2) - 0.7071), C1, C2 the lengths of x1 + x2 - x0 - x3 and
 * x2 + x3 - x0 - x1 (twice the mid-side vectors), h = max(|x1 x x3|, |x0 x x2|) / A about the
 * centroid (0 on a parallelogram): 0.894 of a square's side. */
INLINE vec quad_length_qeph(const quad_frame_t *g, double dn)
{
  const vec *X = g->x, *Y = g->y, A = g->area;
  const vec x13 = 0.5 * (X[0] - X[2]), y13 = 0.5 * (Y[0] - Y[2]);
  const vec x24 = 0.5 * (X[1] - X[3]), y24 = 0.5 * (Y[1] - Y[3]);
  const vec diagonal = vmax(x13 * x13 + y13 * y13, x24 * x24 + y24 * y24);
  const vec h = vmax(vabs(X[1] * Y[3] - Y[1] * X[3]), vabs(X[0] * Y[2] - Y[0] * X[2])) / A;
  const vec rx = X[1] + X[2] - X[0] - X[3], ry = Y[1] + Y[2] - Y[0] - Y[3];
  const vec sx = X[2] + X[3] - X[0] - X[1], sy = Y[2] + Y[3] - Y[0] - Y[1];
  const vec c1 = vsqrt(rx * rx + ry * ry), c2 = vsqrt(sx * sx + sy * sy);
  const vec aspect = 1.0 + vmin(VZERO + 0.5, 0.25 * (vmax(c1, c2) / vmin(c1, c2) - 1.0));
  const vec f = 3.413 * vmax(VZERO, 4.0 * A / (c1 * c2) - 0.7071);
  const vec shape = 2.0 * aspect * (0.78 + 0.22 * f * f * f);
  const double damping = sqrt(1.0 + dn * dn) - dn;
  return (damping * A) / vmax(vsqrt(shape * (1.25 + h) * diagonal), VZERO + 1e-300);
}

/* Radioss's characteristic length (m) of the cells of frame g: CDLEN3's for its
 * Belytschko-Tsay shells, max(A / longest diagonal, shortest side or diagonal) on the
 * cell's projection onto its mid-plane (CDLEN3 takes the in-plane coordinates X2..Y4 of
 * cderi3.F: a warped cell's sides count as their projections), or QEPH's with
 * s->qeph_step. */
INLINE vec quad_length(const shell_params *s, const quad_frame_t *g)
{
  if (s->qeph_step)
    return quad_length_qeph(g, s->qeph_dn);
  vec l2[6];
  static const int PAIRS[6][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {1, 3}};
  for (int e = 0; e < 6; ++e)
  {
    const vec dx = g->x[PAIRS[e][1]] - g->x[PAIRS[e][0]];
    const vec dy = g->y[PAIRS[e][1]] - g->y[PAIRS[e][0]];
    l2[e] = dx * dx + dy * dy;
  }
  vec shortest = l2[0];
  for (int e = 1; e < 6; ++e)
    shortest = vmin(shortest, l2[e]);
  const vec dynamic = g->area * g->area / vmax(l2[4], l2[5]);
  return vsqrt(vmax(dynamic, shortest));
}

/* shell_quad's work on the batch b of cells: forces, state, steps;
 * its energies added to totals[0 .. 2] (stored, hourglass, plastic), batch after batch. */
INLINE void shell_quad_batch(int plastic, const batch_t *bp,
                             const int32_t *restrict cells, const double *restrict X,
                             const double *restrict u, const double *restrict v,
                             const double *restrict w, const element_params *p,
                             const shell_params *s, const qeph_constants_t *qcp,
                             double *restrict state, int64_t stride, double *restrict f,
                             double *restrict m, double *restrict energy,
                             double *restrict step, double *restrict totals)
{
  const batch_t b = *bp;
  const qeph_constants_t qc = *qcp;
  const double dt = p->dt;
  const int warping = s->warping;
  vec Xe[12], ue[12], ve[12], we[12], x[12], xm[12], fe[24], du[24];
  shell_motion(cells, 4, &b, dt, X, u, v, w, Xe, ue, ve, we, x, xm, du, fe);
  const vec t = cell_values(s->thickness, &b);
  quad_frame_t g;
  quad_frame(xm, &g);
  vec vl[4][3], wl[4][3], d[3], k[3], gs[2];
  to_local(&g, ve, vl);
  to_local(&g, we, wl);
  vec Ji[9], mz[4], drill = VZERO;
  if (s->kd > 0.0)
    drill = quad_drill_update(&g, s, dt, t, vl, wl, state, stride, &b, mz);
  if (warping)
  {
    rigid_inverse(&g, Ji);
    project_rigid(&g, Ji, vl);
  }
  quad_strain_rates(&g, vl, wl, d, k, gs);
  const vec mid_area = g.area;
  vec N[3], M[3], Q[2], elastic, dissipated, damage;
  const vec before =
      s->new_thickness ? shell_mean_stress(plastic, s, &b, state, stride, t) : VZERO;
  /* QEPH's hourglass yield reads the material's update of the step (CZFINTN1 after
   * MULAWC): the points' plastic strains before it */
  const int qeph = plastic && s->qeph_hourglass && (s->hk > 0.0 || s->qeph_physical);
  vec eps_before[SHELL_MAX_POINTS];
  for (int pt = 0; qeph && pt < s->points; ++pt)
    eps_before[pt] = load_slot(state, stride, &b, 2 + SHELL_POINT_SLOTS * pt + 3);
  shell_update(plastic, p, s, &b, state, stride, t, d, k, gs, N, M, Q, &elastic, &dissipated,
               &damage);
  qeph_material_t material;
  if (qeph)
    qeph_material(p, s, &b, state, stride, eps_before, t, N, M, &material);
  vec hourglass = VZERO;
  if (s->hm > 0.0 || s->hf > 0.0 || s->hr > 0.0 || s->hk > 0.0 || s->qeph_physical)
    hourglass = quad_hourglass(&g, s, &qc, p->density, dt, t, warping, Ji, vl, wl, state,
                               stride, &b, qeph ? &material : NULL, fe);
  if (s->new_thickness)
    shell_thickness_change(s, &b, t, d, before, (N[0] + N[1]) / t);
  quad_frame(x, &g);
  if (warping)
    rigid_inverse(&g, Ji);
  quad_resultant_forces(&g, warping, Ji, N, M, Q, fe);
  if (s->kd > 0.0)
    quad_drill_forces(&g, mz, fe);
  elastic = elastic * g.area + drill;
  const vec plastic_work = dissipated * mid_area;
  const ivec inverted = ~(g.area > 0.0);
  vec dte = VZERO + INFINITY;
  if (p->estimate)
    dte = (p->calibration / s->bar_speed) * quad_length(s, &g);
  const ivec failed = erode_plastic(p, &b, damage, inverted, dte, elastic, plastic_work,
                                    &hourglass, du, fe, 8, energy, step);
  totals[0] += lane_sum(vselect(failed, VZERO, elastic), b.nb);
  totals[1] += lane_sum(hourglass, b.nb);
  totals[2] += lane_sum(plastic_work, b.nb);
  scatter_add(cells, 4, &b, fe, f);
  scatter_add(cells, 4, &b, fe + 12, m);
  note_inverted(inverted & ~failed, &b, x, NULL, 4, step);
  if (p->estimate)
    note_steps(p, vselect(inverted | failed, VZERO + INFINITY, dte), &b, cells, x, NULL, 4, step);
}

/* The cells k0 .. k0 + LANES - 1 as a batch that the compiler knows to be consecutive. */
INLINE batch_t run_at(int64_t k0)
{
  batch_t b;
  b.nb = LANES, b.run = 1;
  for (int k = 0; k < LANES; ++k)
    b.id[k] = k0 + k;
  return b;
}

/* The quadrilaterals' work batch after batch.  `runs` (a constant; only without p->live):
 * the full batches are compiled apart as runs of consecutive cells (run_at), whose state
 * rows and thicknesses load and store as vectors with no branches; the last, short batch
 * goes through batch_at.  The energies add up batch after batch in the cells' order. */
INLINE void shell_quad(int plastic, int runs, int64_t num_cells, const int32_t *restrict cells,
                       const double *restrict X, const double *restrict u,
                       const double *restrict v, const double *restrict w,
                       const element_params *p, const shell_params *s, double *restrict state,
                       int64_t stride, double *restrict f, double *restrict m,
                       double *restrict energy, double *restrict step)
{
  const qeph_constants_t qc = qeph_constants(s);
  double totals[3] = {0.0, 0.0, 0.0};
  int64_t k0 = 0;
  if (runs && !p->live)
    for (; k0 + LANES <= num_cells; k0 += LANES)
    {
      const batch_t b = run_at(k0);
      shell_quad_batch(plastic, &b, cells, X, u, v, w, p, s, &qc, state, stride,
                       f, m, energy, step, totals);
    }
  for (; k0 < num_cells; k0 += LANES)
  {
    const batch_t b = batch_at(p->live, k0, num_cells);
    shell_quad_batch(plastic, &b, cells, X, u, v, w, p, s, &qc, state, stride, f,
                     m, energy, step, totals);
  }
  energy[0] += totals[0];
  energy[1] += totals[1];
  energy[2] += totals[2];
}

/* f += internal forces (N), m += internal moments (N m) of the quadrilaterals `cells` (n x 4,
 * counter-clockwise), nodes at X + u (m), velocities v (m/s) and angular velocities w
 * (rad/s, global); the state rows as the header says; energies and steps as above. */
void shell_quad_elastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                        const double *v, const double *w, const element_params *p,
                        const shell_params *s, double *state, int64_t stride, double *f,
                        double *m, double *energy, double *step)
{
  shell_quad(0, 0, n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
}

/* QEPH's cells as Radioss decks give them (Ishell 24: its physical hourglass stresses with
 * their yield, the warping correction, QEPH's step) with none of the options that shell_quad
 * tests cell batch by cell batch: no viscous or elastic BT hourglass coefficients, drilling,
 * thickness change, failure, erosion, heating or flow-stress cap, and 5 points.  For them
 * shell_quad is compiled apart (qeph_plain_kernel) on a copy of the parameters with those
 * settings as constants, once for linear hardening (the law a constant too) and once for the
 * other laws: the compiler folds them, so that the branches, the work only the options need
 * (the increments of erosion, the linear law's other forms in the return) and the runtime
 * loops over the points go.  The arithmetic is the same, in the same order, but for the
 * full batches, known there to be runs of consecutive cells (shell_quad's `runs`): without
 * the branches of their loads and stores GCC contracts more products into fused
 * multiply-adds, and the results change in their last bits.  (The power law as a constant
 * as well would gain about 1 % more and change the last bits too: some of its products by a
 * factor 1 fold, and GCC then contracts their neighbours into other fused multiply-adds.) */
INLINE int qeph_plain(const element_params *p, const shell_params *s)
{
  return s->qeph_physical && s->qeph_hourglass && s->warping && s->points == 5
         && s->hm == 0.0 && s->hf == 0.0 && s->hr == 0.0 && s->hk == 0.0 && s->kd == 0.0
         && !s->new_thickness && !p->failure && !p->erode && !p->live && !p->cell_work
         && !p->thermal && !(p->max_flow_stress > 0.0);
}

/* shell_quad of elasto-plastic cells for which qeph_plain holds; `linear`: of a linear law. */
INLINE void qeph_plain_kernel(int linear, int64_t n, const int32_t *cells, const double *X,
                              const double *u, const double *v, const double *w,
                              const element_params *p, const shell_params *s, double *state,
                              int64_t stride, double *f, double *m, double *energy,
                              double *step)
{
  element_params pc = *p; /* a copy that nothing else can write: its constants fold */
  shell_params sc = *s;
  if (linear)
    pc.hardening = HARDENING_LINEAR;
  pc.failure = 0, pc.erode = 0, pc.live = NULL, pc.cell_work = NULL, pc.thermal = 0;
  pc.max_flow_stress = 0.0;
  sc.qeph_physical = 1, sc.qeph_hourglass = 1, sc.warping = 1, sc.points = 5;
  sc.hm = sc.hf = sc.hr = sc.hk = sc.kd = 0.0;
  sc.new_thickness = NULL;
  shell_quad(1, 1, n, cells, X, u, v, w, &pc, &sc, state, stride, f, m, energy, step);
}

/* Each its own function (noinline): two instances of shell_quad in one function would
 * compile worse. */
static __attribute__((noinline)) void
qeph_plain_linear(int64_t n, const int32_t *cells, const double *X, const double *u,
                  const double *v, const double *w, const element_params *p,
                  const shell_params *s, double *state, int64_t stride, double *f, double *m,
                  double *energy, double *step)
{
  qeph_plain_kernel(1, n, cells, X, u, v, w, p, s, state, stride, f, m, energy,
                    step);
}

static __attribute__((noinline)) void
qeph_plain_other(int64_t n, const int32_t *cells, const double *X, const double *u,
                 const double *v, const double *w, const element_params *p,
                 const shell_params *s, double *state, int64_t stride, double *f, double *m,
                 double *energy, double *step)
{
  qeph_plain_kernel(0, n, cells, X, u, v, w, p, s, state, stride, f, m, energy,
                    step);
}

static __attribute__((noinline)) void
shell_quad_general(int64_t n, const int32_t *cells, const double *X, const double *u,
                   const double *v, const double *w, const element_params *p,
                   const shell_params *s, double *state, int64_t stride, double *f, double *m,
                   double *energy, double *step)
{
  shell_quad(1, 0, n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
}

void shell_quad_plastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                        const double *v, const double *w, const element_params *p,
                        const shell_params *s, double *state, int64_t stride, double *f,
                        double *m, double *energy, double *step)
{
  if (!qeph_plain(p, s))
    shell_quad_general(n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
  else if (p->hardening == HARDENING_LINEAR)
    qeph_plain_linear(n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
  else
    qeph_plain_other(n, cells, X, u, v, w, p, s, state, stride, f, m, energy, step);
}

/* The projected area (m^2) and characteristic length (m) of each quadrilateral at x (the
 * length as s's rule). */
void shell_quad_sizes(const shell_params *s, int64_t n, const int32_t *cells, const double *x,
                      double *area, double *length)
{
  vec xe[12];
  for (int64_t k0 = 0; k0 < n; k0 += LANES)
  {
    const batch_t b = batch_at(NULL, k0, n);
    gather(cells, 4, &b, x, xe);
    quad_frame_t g;
    quad_frame(xe, &g);
    const vec l = quad_length(s, &g);
    for (int k = 0; k < b.nb; ++k)
    {
      area[k0 + k] = g.area[k];
      length[k0 + k] = l[k];
    }
  }
}

/* The plane-stress point update of shell.h at one point (for tests and material drivers):
 * stress (xx, yy, xy; Pa), plastic strain and temperature in place from the strain increment
 * de (xx, yy, gamma_xy); returns the plastic dissipation density (J/m^3). */
double shell_point(const element_params *p, const shell_params *s, double sigma[3],
                   double *eps_p, double *T, const double de[3])
{
  vec sig[1][3], e[1] = {VZERO + *eps_p}, temperature[1] = {VZERO + *T}, d[1][3];
  for (int i = 0; i < 3; ++i)
  {
    sig[0][i] = VZERO + sigma[i];
    d[0][i] = VZERO + de[i];
  }
  point_step done[1];
  vec dissipation[1];
  shell_points_update(p, s, 1, sig, e, temperature, d, done, dissipation);
  for (int i = 0; i < 3; ++i)
    sigma[i] = sig[0][i][0];
  *eps_p = e[0][0];
  *T = temperature[0][0];
  return dissipation[0][0];
}
