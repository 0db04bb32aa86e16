/* The rigid-wall condition on the nodes of a wall's near set (rwall_fem/walls/constraint.py;
 * docs/theory.md, "Rigid walls"), node by node in one pass each:
 *
 * wall_find: predict each node, v* = v^{n-1/2} + dt^n a^n and x* = x^n + dt^{n+1/2} v*,
 *   test it against the wall at its predicted position (behind the surface; on a
 *   parallelogram inside it and at most two steps of normal travel behind it) and list
 *   the nodes in contact with what the response needs of them.
 * wall_impulses: the normal and tangential impulses (free, tied, Coulomb with the
 *   friction filter of friction.h, the law the contact interfaces share) of the listed
 *   nodes for a wall velocity.
 * wall_apply: add the impulses to a^n and sum what the wall books (impulses, works).
 * wall_work: the sums of impulse . (v - V) over listed nodes (the halves of the works).
 * wall_coupling: the sums over the listed nodes of a main-node wall's equations (the
 *   mass each node lends the wall and the momentum it brings); wall_velocity: those
 *   equations assembled, and solved when they are diagonal.
 * wall_clearance: how far each secondary node is from being treated (selects the near set).
 * largest_components: the largest |v_i| and |a_i| of the secondary nodes (how far the
 *   near set may be trusted); largest_range: the same for a range of nodes.
 *
 * The arithmetic is that of the NumPy code these replace, operation for operation and in
 * the same order, so that results stay the same to the bit: dot products of 3 components
 * as NumPy's matrix products with the reference BLAS ((x0 y0 + x1 y1) + x2 y2; those of
 * impulses as its einsum, (x0 y0 + x2 y2) + x1 y1); sums over the nodes as NumPy's
 * reductions (numpy_sum: pairwise in blocks of its buffer); no fused multiply-add.
 */
#include "batch.h"
#include "friction.h"

#pragma GCC optimize("fp-contract=off")

enum
{
  WALL_PLANE = 0,
  WALL_PARALLELOGRAM = 1,
  WALL_CYLINDER = 2,
  WALL_SPHERE = 3
};

enum
{
  SLIDE_FREE = 0,
  SLIDE_TIED = 1,
  SLIDE_FRICTION = 2
};

/* What wall_find needs of the wall's shape (walls/shapes.py). */
typedef struct
{
  int kind;           /* WALL_PLANE, ... */
  double point[3];    /* M, m */
  double normal[3];   /* planes: unit normal toward the allowed side */
  double dual[6];     /* parallelogram: (a, b) = dual (x - M), rows of 3 */
  double widths[2];   /* parallelogram: its widths across the sides (m) */
  double axis[3];     /* cylinder: unit axis */
  double radius;      /* round walls, m */
  double fallback[3]; /* round walls: the normal of a node on the axis or at the centre */
} wall_shape;

/* NumPy's pairwise sum of n doubles (its float64 add.reduce of one contiguous block). */
static double pairwise_sum(const double *a, int64_t n)
{
  if (n < 8)
  {
    double res = 0.0;
    for (int64_t i = 0; i < n; ++i)
      res += a[i];
    return res;
  }
  if (n <= 128)
  {
    double r[8];
    for (int j = 0; j < 8; ++j)
      r[j] = a[j];
    int64_t i;
    for (i = 8; i < n - (n % 8); i += 8)
      for (int j = 0; j < 8; ++j)
        r[j] += a[i + j];
    double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; ++i)
      res += a[i];
    return res;
  }
  int64_t n2 = n / 2;
  n2 -= n2 % 8;
  return pairwise_sum(a, n2) + pairwise_sum(a + n2, n - n2);
}

/* NumPy's a.sum() of a contiguous float64 array: pairwise sums of blocks of its iterator's
 * buffer (8192 values), added in turn to 0. */
double numpy_sum(int64_t n, const double *a)
{
  double total = 0.0;
  for (int64_t i = 0; i < n; i += 8192)
    total += pairwise_sum(a + i, n - i < 8192 ? n - i : 8192);
  return total;
}

INLINE double dot_blas(const double x[3], const double y[3])
{
  return (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2];
}

INLINE double dot_einsum(const double x[3], const double y[3])
{
  return (x[0] * y[0] + x[2] * y[2]) + x[1] * y[1];
}

INLINE double norm3(const double x[3])
{
  return sqrt((x[0] * x[0] + x[1] * x[1]) + x[2] * x[2]);
}

/* The vector from the wall's centre (or axis) to x, for a wall translated to `at`. */
INLINE void radial(const wall_shape *s, const double x[3], const double at[3], double r[3])
{
  for (int c = 0; c < 3; ++c)
    r[c] = x[c] - (s->point[c] + at[c]);
  if (s->kind == WALL_CYLINDER)
  {
    const double along = dot_blas(r, s->axis);
    for (int c = 0; c < 3; ++c)
      r[c] = r[c] - along * s->axis[c];
  }
}

/* Signed distance (m) of x to the surface of the wall translated to `at`. */
INLINE double distance(const wall_shape *s, const double x[3], const double at[3])
{
  double r[3];
  if (s->kind == WALL_PLANE || s->kind == WALL_PARALLELOGRAM)
  {
    for (int c = 0; c < 3; ++c)
      r[c] = x[c] - (s->point[c] + at[c]);
    return dot_blas(r, s->normal);
  }
  radial(s, x, at, r);
  return norm3(r) - s->radius;
}

/* Whether x projects inside the parallelogram translated to `at`. */
INLINE int inside_patch(const wall_shape *s, const double x[3], const double at[3])
{
  double r[3];
  for (int c = 0; c < 3; ++c)
    r[c] = x[c] - (s->point[c] + at[c]);
  const double a = dot_blas(r, s->dual), b = dot_blas(r, s->dual + 3);
  return a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0;
}

/* The unit normal (toward the allowed side) at x of the wall translated to `at`. */
INLINE void normal_at(const wall_shape *s, const double x[3], const double at[3], double n[3])
{
  if (s->kind == WALL_PLANE || s->kind == WALL_PARALLELOGRAM)
  {
    for (int c = 0; c < 3; ++c)
      n[c] = s->normal[c];
    return;
  }
  double r[3];
  radial(s, x, at, r);
  const double length = norm3(r);
  if (length <= 1e-12 * s->radius)
  {
    for (int c = 0; c < 3; ++c)
      n[c] = s->fallback[c];
    return;
  }
  /* NumPy's maximum(length, 1e-300): NaN stays NaN. */
  const double divisor = (length >= 1e-300 || isnan(length)) ? length : 1e-300;
  for (int c = 0; c < 3; ++c)
    n[c] = r[c] / divisor;
}

/* NumPy's maximum(a, b): NaN if a or b is NaN. */
INLINE double nan_max(double a, double b)
{
  return (a >= b || isnan(a)) ? a : b;
}

/* The clearance (m) of the n nodes `nodes` (indices into X and u) from the wall at
 * `offset`, as walls/shapes.py's clearance: a lower bound on how far a node must travel
 * relative to the wall before the wall can treat it.  Returns the largest |x_i| of their
 * positions x = X + u (m; NaN if one is NaN). */
double wall_clearance(int64_t n, const int64_t *restrict nodes, const double *restrict X,
                      const double *restrict u, const wall_shape *s, const double offset[3],
                      double *restrict clearance)
{
  double largest = 0.0;
  int bad = 0;
  for (int64_t i = 0; i < n; ++i)
  {
    const int64_t node = nodes[i];
    double x[3];
    for (int c = 0; c < 3; ++c)
    {
      x[c] = X[3 * node + c] + u[3 * node + c];
      bad |= isnan(x[c]);
      largest = fabs(x[c]) > largest ? fabs(x[c]) : largest;
    }
    double d = distance(s, x, offset);
    if (s->kind == WALL_PARALLELOGRAM)
    {
      double r[3];
      for (int c = 0; c < 3; ++c)
        r[c] = x[c] - (s->point[c] + offset[c]);
      double beside = -INFINITY;
      for (int k = 0; k < 2; ++k)
      {
        const double ab = dot_blas(r, s->dual + 3 * k);
        beside = nan_max(beside, nan_max(-ab, ab - 1.0) * s->widths[k]);
      }
      d = nan_max(d, beside);
    }
    clearance[i] = d;
  }
  return bad ? NAN : largest;
}

/* Test the n nodes `near` (indices into the node arrays X, u, v, a of shape (nodes, 3), and
 * mass) against the wall at `offset` now and `next` after the step, the wall moving at
 * `velocity` (m/s) over it.  Lists the k nodes in contact, in the order of `near`: their
 * positions in it (hits), node indices, masses (kg), normals, v* and v^{n-1/2} (m/s,
 * rows of 3) and the normal velocity relative to the wall they must have after the step
 * (target, m/s: 0, or what brings a node behind a parallelogram back onto it in one step).
 * Returns k. */
int64_t wall_find(int64_t n, const int64_t *restrict near, const double *restrict X,
                  const double *restrict u, const double *restrict v, const double *restrict a,
                  const double *restrict mass, double dt_v, double dt, const wall_shape *s,
                  const double offset[3], const double next[3], const double velocity[3],
                  int64_t *restrict hits, int64_t *restrict nodes, double *restrict m,
                  double *restrict normals, double *restrict vs, double *restrict v_old,
                  double *restrict target)
{
  const int finite = s->kind == WALL_PARALLELOGRAM;
  int64_t k = 0;
  for (int64_t i = 0; i < n; ++i)
  {
    const int64_t node = near[i];
    double vo[3], vp[3], xn[3], xp[3];
    for (int c = 0; c < 3; ++c)
    {
      vo[c] = v[3 * node + c];
      vp[c] = vo[c] + dt_v * a[3 * node + c];
      xn[c] = X[3 * node + c] + u[3 * node + c];
      xp[c] = xn[c] + dt * vp[c];
    }
    if (!(distance(s, xp, next) < 0.0))
      continue;
    double goal = 0.0;
    if (finite)
    {
      if (!inside_patch(s, xp, next))
        continue;
      const double d_now = distance(s, xn, offset);
      double w[3];
      for (int c = 0; c < 3; ++c)
        w[c] = vp[c] - velocity[c];
      const double normal_speed = fabs(dot_blas(w, s->normal));
      if (!(d_now >= (-2.0 * dt) * normal_speed)) /* deeper nodes pass behind the wall */
        continue;
      const double depth = -d_now; /* NumPy's maximum(-d, 0): NaN stays NaN */
      goal = ((depth >= 0.0 || isnan(depth)) ? depth : 0.0) / dt;
    }
    hits[k] = i;
    nodes[k] = node;
    m[k] = mass[node];
    normal_at(s, xn, offset, normals + 3 * k);
    for (int c = 0; c < 3; ++c)
    {
      vs[3 * k + c] = vp[c];
      v_old[3 * k + c] = vo[c];
    }
    target[k] = goal;
    ++k;
  }
  return k;
}

/* The impulses (N s) on the k listed nodes of masses m (kg), normals n, predicted
 * velocities vs (m/s) and target normal velocities (m/s) from a wall moving at `velocity`
 * (m/s): normal, and for slide != SLIDE_FREE tangential (rows of 3) and whether the node
 * slips (Coulomb: friction |I_N|; the filter mixes alpha of the sticking impulse with
 * 1 - alpha of `kept`, the previous step's, when kept is not NULL). */
void wall_impulses(int64_t k, int slide, double friction, double alpha,
                   const double *restrict m, const double *restrict n,
                   const double *restrict vs, const double velocity[3],
                   const double *restrict target, const double *restrict kept,
                   double *restrict normal, double *restrict tangential, uint8_t *restrict slip)
{
  for (int64_t i = 0; i < k; ++i)
  {
    const double *ni = n + 3 * i;
    double w[3];
    for (int c = 0; c < 3; ++c)
      w[c] = vs[3 * i + c] - velocity[c];
    const double wn = dot_einsum(w, ni);
    const double push = m[i] * (target[i] - wn);
    for (int c = 0; c < 3; ++c)
      normal[3 * i + c] = push * ni[c];
    if (slide == SLIDE_FREE)
      continue;
    double *stick = tangential + 3 * i;
    for (int c = 0; c < 3; ++c)
      stick[c] = -m[i] * (w[c] - wn * ni[c]);
    slip[i] = 0;
    if (slide == SLIDE_TIED)
      continue;
    const double limit = friction * norm3(normal + 3 * i);
    slip[i] = coulomb_law(stick, kept ? kept + 3 * i : NULL, alpha, limit);
  }
}

/* sum over the k listed nodes of impulse . (v - velocity) (N m/s), v rows of 3 at the
 * node indices `nodes` (when not NULL; else the rows of v themselves), as NumPy's
 * (impulse * (v[nodes] - velocity)).sum(): out[0] for `normal`, out[1] for `tangential`
 * (0 when NULL); `scratch` holds 3 k values. */
void wall_work(int64_t k, const int64_t *restrict nodes, const double *restrict normal,
               const double *restrict tangential, const double *restrict v,
               const double velocity[3], double *restrict scratch, double out[2])
{
  const double *impulses[2] = {normal, tangential};
  for (int j = 0; j < 2; ++j)
  {
    const double *impulse = impulses[j];
    out[j] = 0.0;
    if (!impulse)
      continue;
    for (int64_t i = 0; i < k; ++i)
    {
      const int64_t row = nodes ? nodes[i] : i;
      for (int c = 0; c < 3; ++c)
        scratch[3 * i + c] = impulse[3 * i + c] * (v[3 * row + c] - velocity[c]);
    }
    out[j] = numpy_sum(3 * k, scratch);
  }
}

/* The sums over the k listed nodes (masses m, kg; normals n; v* vs, m/s; target normal
 * velocities, m/s) of the equations of a main-node wall's velocity (walls/constraint.py,
 * _coupled_velocity): out[0..8] = sum m_i P_i (rows of 3), out[9..11] = sum m_i P_i v*_i
 * - sum m_i b_i n_i [- sum of the extra impulses], P_i the identity for a tied node and
 * n_i n_i^T for another.  Without `slip` every node is tied when `tied` is not 0; with it,
 * the nodes that do not slip are tied and the slipping ones bring their `tangential`
 * impulses (N s) as extra.  Sums in the order of NumPy's einsum and axis-0 sums: node after
 * node, the three products of a row of P_i v*_i summed before they join the total. */
void wall_coupling(int64_t k, int tied, const uint8_t *restrict slip, const double *restrict m,
                   const double *restrict n, const double *restrict vs,
                   const double *restrict target, const double *restrict tangential,
                   double out[12])
{
  double M[9] = {0.0}, R[3] = {0.0}, S[3] = {0.0}, E[3] = {0.0};
  for (int64_t i = 0; i < k; ++i)
  {
    const double *ni = n + 3 * i, *vi = vs + 3 * i;
    const int held = slip ? !slip[i] : tied;
    double P[9];
    for (int j = 0; j < 3; ++j)
      for (int c = 0; c < 3; ++c)
        P[3 * j + c] = held ? (j == c ? 1.0 : 0.0) : ni[j] * ni[c];
    const double mb = m[i] * target[i];
    for (int j = 0; j < 3; ++j)
    {
      double accum = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        const double mp = m[i] * P[3 * j + c];
        M[3 * j + c] += mp;
        accum += mp * vi[c];
      }
      R[j] = accum + R[j];
      S[j] += mb * ni[j];
      if (slip)
        E[j] += slip[i] ? tangential[3 * i + j] : 0.0;
    }
  }
  for (int c = 0; c < 9; ++c)
    out[c] = M[c];
  for (int j = 0; j < 3; ++j)
    out[9 + j] = slip ? (R[j] - S[j]) - E[j] : R[j] - S[j];
}

/* The equations of a main-node wall's velocity V (kg, N s) from the sums `total` of
 * wall_coupling (over all ranks): matrix = mass I + total[0..8], rhs = mass V* + total[9..11],
 * the rows of the `held` components (held[j] not 0) replaced by V_j = V*_j.  When the
 * matrix is diagonal (all nodes tied), finite and without zero on its diagonal, V =
 * rhs / diagonal (what LAPACK's solve gives such a system, to the bit) and returns 1;
 * else returns 0 (the caller solves). */
int wall_velocity(const double total[12], double mass, const double predicted[3],
                  const uint8_t held[3], double matrix[9], double rhs[3], double out[3])
{
  int diagonal = 1;
  for (int j = 0; j < 3; ++j)
  {
    for (int c = 0; c < 3; ++c)
    {
      const double eye = j == c ? 1.0 : 0.0;
      matrix[3 * j + c] = held[j] ? eye : mass * eye + total[3 * j + c];
      if (j != c && matrix[3 * j + c] != 0.0)
        diagonal = 0;
    }
    rhs[j] = held[j] ? predicted[j] : mass * predicted[j] + total[9 + j];
    const double d = matrix[4 * j];
    if (!isfinite(d) || d == 0.0 || !isfinite(rhs[j]))
      diagonal = 0;
  }
  if (!diagonal)
    return 0;
  for (int j = 0; j < 3; ++j)
    out[j] = rhs[j] / matrix[4 * j];
  return 1;
}

/* wall_coupling and wall_velocity in one call (one rank: the sums are the totals): out[0..11]
 * the sums, out[12..20] the matrix, out[21..23] the right side, out[24..26] V if solved;
 * returns whether it was. */
int wall_coupled(int64_t k, int tied, const uint8_t *restrict slip, const double *restrict m,
                 const double *restrict n, const double *restrict vs,
                 const double *restrict target, const double *restrict tangential, double mass,
                 const double predicted[3], const uint8_t held[3], double out[27])
{
  wall_coupling(k, tied, slip, m, n, vs, target, tangential, out);
  return wall_velocity(out, mass, predicted, held, out + 12, out + 21, out + 24);
}

/* The largest absolute values of the n values of v and of a (contiguous: the rows of a
 * range of nodes), NaN values left out, in out[0] and out[1]: largest_components on
 * nodes that follow one another, in independent lanes. */
void largest_range(int64_t n, const double *restrict v, const double *restrict a,
                   double out[2])
{
  double mv[8] = {0.0}, ma[8] = {0.0};
  int64_t i = 0;
  for (; i + 8 <= n; i += 8)
    for (int j = 0; j < 8; ++j)
    {
      const double x = fabs(v[i + j]), y = fabs(a[i + j]);
      mv[j] = x > mv[j] ? x : mv[j];
      ma[j] = y > ma[j] ? y : ma[j];
    }
  for (int j = 0; i < n; ++i, ++j)
  {
    const double x = fabs(v[i]), y = fabs(a[i]);
    mv[j] = x > mv[j] ? x : mv[j];
    ma[j] = y > ma[j] ? y : ma[j];
  }
  out[0] = out[1] = 0.0;
  for (int j = 0; j < 8; ++j)
  {
    out[0] = mv[j] > out[0] ? mv[j] : out[0];
    out[1] = ma[j] > out[1] ? ma[j] : out[1];
  }
}

/* Add the impulses (normal, plus tangential unless NULL; N s) of the k listed nodes to
 * their accelerations a^n as impulse / (m dt_v), and sum over the nodes (in order):
 * out[0..2] the normal impulses, out[3..5] the tangential ones, out[6..8] both (N s); then
 * the works' halves at v^{n-1/2} (`previous`, rows of 3) relative to the wall's velocity
 * `before` (wall_work: works[0] normal, works[1] tangential; scratch of 3 k values). */
void wall_apply(int64_t k, const int64_t *restrict nodes, const double *restrict m,
                const double *restrict normal, const double *restrict tangential, double dt_v,
                double *restrict a, double out[9], const double *restrict previous,
                const double before[3], double *restrict scratch, double works[2])
{
  for (int c = 0; c < 9; ++c)
    out[c] = 0.0;
  for (int64_t i = 0; i < k; ++i)
  {
    const double scale = m[i] * dt_v;
    for (int c = 0; c < 3; ++c)
    {
      const double t = tangential ? tangential[3 * i + c] : 0.0;
      const double impulse = tangential ? normal[3 * i + c] + t : normal[3 * i + c];
      a[3 * nodes[i] + c] += impulse / scale;
      out[c] += normal[3 * i + c];
      out[3 + c] += t;
      out[6 + c] += impulse;
    }
  }
  wall_work(k, NULL, normal, tangential, previous, before, scratch, works);
}

/* The largest velocity and acceleration components |v_i| and |a_i| of the n nodes `nodes`
 * (rows of v and a), NaN values left out (a node with one is never treated: its test
 * fails).  The largest of values is exact in any order: two nodes at a time, in
 * independent chains of comparisons. */
INLINE void fold(const double *restrict row, double m[3])
{
  for (int c = 0; c < 3; ++c)
  {
    const double x = fabs(row[c]);
    m[c] = x > m[c] ? x : m[c];
  }
}

void largest_components(int64_t n, const int64_t *restrict nodes, const double *restrict v,
                        const double *restrict a, double out[2])
{
  double v0[3] = {0.0, 0.0, 0.0}, v1[3] = {0.0, 0.0, 0.0};
  double a0[3] = {0.0, 0.0, 0.0}, a1[3] = {0.0, 0.0, 0.0};
  int64_t i = 0;
  for (; i + 1 < n; i += 2)
  {
    const int64_t p = 3 * nodes[i], q = 3 * nodes[i + 1];
    fold(v + p, v0);
    fold(v + q, v1);
    fold(a + p, a0);
    fold(a + q, a1);
  }
  if (i < n)
  {
    fold(v + 3 * nodes[i], v0);
    fold(a + 3 * nodes[i], a0);
  }
  fold(v1, v0);
  fold(a1, a0);
  out[0] = v0[0] > v0[1] ? v0[0] : v0[1];
  out[0] = v0[2] > out[0] ? v0[2] : out[0];
  out[1] = a0[0] > a0[1] ? a0[0] : a0[1];
  out[1] = a0[2] > out[1] ? a0[2] : out[1];
}
