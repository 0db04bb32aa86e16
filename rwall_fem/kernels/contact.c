/* Node-to-surface penalty contact (Radioss /INTER/TYPE7; rwall_fem/contact/, docs/theory.md,
 * "Contact between parts").  All arrays index a rank's local nodes of the interface (its
 * owned surface nodes, then the other ranks' nodes of the segments near its secondary
 * nodes), rows of 3 for vectors.
 * A segment is 4 node indices: a quadrilateral, or a triangle whose 4th is -1.
 *
 * contact_moved: the largest squared distance a node moved since the last sort.
 * contact_sort: the candidate segments of each secondary node, by buckets (spatial hashing):
 *   the secondary nodes go into a grid of cubes, each segment is tested against the nodes
 *   of the cubes its box (widened by its reach) overlaps; a node's own segments (those
 *   holding it: self-contact) are left out, as OpenRadioss's sort leaves them
 *   (i7trivox.F), and the nodes each segment's list leaves out (`removed`, Radioss
 *   Irem_gap 2: contact_remove.c).  The lists come sorted by segment, whatever the grid.
 * contact_near: the candidates near enough to their node to be met before the nodes have
 *   moved a skin (a list within the sort's list, which the passes then go through).
 * contact_initial_gaps: the gaps of the nodes that start inside the gap (Radioss Inacti 6).
 * The near lists and the passes find the distance of a node to its candidates LANES pairs
 * at once without a branch (candidate_distances), and only those within reach get their
 * closest point.
 * contact_forces: one pass of the secondary nodes against their candidates: the closest
 *   point on the surface (closest_on_surface: the segments within a band of the closest
 *   distance blended, a quadrilateral as 4 triangles about its centre, the side from the
 *   blended pseudo-normal), the penalty force of the penetration p = g - d (g the node's
 *   gap, d the signed distance, < 0 behind the surface) stiffening toward p = g
 *   (k0 g / (g - p), held beyond p = cap g), Coulomb
 *   friction on an elastic tangential spring of stiffness k0 (friction.h's law and filter),
 *   added to `force` (N) and the contact stiffness of each node to `stiffness` (N/m): the
 *   tangent of the springs in contact, k0 for those within reach of a segment but not in
 *   contact (so that the step does not jump as nodes come and go).
 * contact_read, contact_apply: the sweeps of the rank's owned surface nodes before the
 *   passes (the state's values in; the books of the previous step's forces; how far the
 *   nodes moved since the sort and the near lists) and after them (the forces out to the
 *   accelerations; the nodal stable step min sqrt(m / (e + k / 2)) (s), e the cells'
 *   term; force and k zeroed).
 * A segment of negative depth -t/2 is a shell's mid-surface with both sides active (the
 * distance to it unsigned); with `half_thickness` the gap is variable, per pair (pair_gap).
 * With `share` and `planes`, a model cut by symmetry planes acts as the whole model would
 * (see mirror).
 */
#include <stdlib.h>

#include "batch.h"
#include "friction.h"

typedef struct
{
  double gap;      /* m */
  double cap;      /* the penetration ratio p / gap beyond which the stiffness stays */
  double friction; /* Coulomb's mu (0: none) */
  double damping;  /* the normal damping's fraction of critical (Radioss VISs) */
  double alpha;    /* the friction filter's weight of the new force (1: no filter) */
  double dt;       /* dt^{n-1/2}, s: the step of the velocities v^{n-1/2} */
  double reach;    /* m: the segments this near a node compete for it (max of gap, depths) */
  double moved;    /* m: the farthest a node has moved since the near lists (contact_near) */
  double gap_max;  /* m: a pair's variable gap at most this (Radioss Gap_max; inf: none) */
  const double *half_thickness; /* m per surface node (half its thickest shell), or NULL:
                                  a constant gap (see pair_gap) */
  const double *node_size;      /* m per surface node, with half_thickness: %mesh_size x the
                                  shortest side of its shells (INFINITY: none; see pair_gap) */
  const double *share;          /* per surface node, or NULL (all 1): the share of the whole
                                  node a model cut by symmetry planes holds (see mirror) */
  const int8_t *planes;         /* per surface node, or NULL: bit c set on a symmetry plane
                                  normal to axis c */
} contact_params;

INLINE double cdot(const double x[3], const double y[3])
{
  return (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2];
}

INLINE void csub(const double *a, const double *b, double r[3])
{
  for (int c = 0; c < 3; ++c)
    r[c] = a[c] - b[c];
}

INLINE void ccross(const double a[3], const double b[3], double r[3])
{
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

/* The larger of `largest` and the squared distance (m^2) from x0 to x; NaN once some is. */
INLINE double farther(double largest, const double x[3], const double x0[3])
{
  const double dx = x[0] - x0[0], dy = x[1] - x0[1], dz = x[2] - x0[2];
  const double d = dx * dx + dy * dy + dz * dz;
  return d > largest || isnan(d) ? d : largest;
}

double contact_moved(int64_t n, const double *restrict x, const double *restrict x0)
{
  double largest = 0.0;
  for (int64_t i = 0; i < 3 * n; i += 3)
    largest = farther(largest, x + i, x0 + i);
  return largest;
}

/* Whether node s is in the sorted list [from, to). */
static int listed(int64_t s, const int64_t *from, const int64_t *to)
{
  while (from < to)
  {
    const int64_t *mid = from + (to - from) / 2;
    if (*mid == s)
      return 1;
    if (*mid < s)
      from = mid + 1;
    else
      to = mid;
  }
  return 0;
}

/* Candidates of the nsec secondary nodes `secondary` among the nseg segments `segs`, each
 * widened by reach[j] (m), at positions x; segment j leaves out the nodes
 * removed[removed_offsets[j] .. removed_offsets[j + 1]) (sorted; removed NULL: none).
 * Fills offsets (nsec + 1) and up to `capacity`
 * candidates (segment indices, sorted per node); `work` holds 2 nsec + 2 capacity + 1
 * int64.  Returns the number of candidates (more than capacity: call again with room). */
int64_t contact_sort(int64_t nsec, const int64_t *restrict secondary, int64_t nseg,
                     const int64_t *restrict segs, const double *restrict reach,
                     const double *restrict x, const int64_t *restrict removed_offsets,
                     const int64_t *restrict removed, int64_t capacity,
                     int64_t *restrict offsets, int64_t *restrict candidates,
                     int64_t *restrict work)
{
  for (int64_t i = 0; i <= nsec; ++i)
    offsets[i] = 0;
  if (nsec == 0 || nseg == 0)
    return 0;
  /* The grid over the secondary nodes' box, from the largest widened segment box. */
  double low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int64_t i = 0; i < nsec; ++i)
    for (int c = 0; c < 3; ++c)
    {
      const double xc = x[3 * secondary[i] + c];
      low[c] = xc < low[c] ? xc : low[c];
      high[c] = xc > high[c] ? xc : high[c];
    }
  double h = 0.0;
  for (int64_t j = 0; j < nseg; ++j)
    for (int c = 0; c < 3; ++c)
    {
      double a = INFINITY, b = -INFINITY;
      for (int k = 0; k < 4; ++k)
      {
        const int64_t node = segs[4 * j + k];
        if (node < 0)
          continue;
        a = x[3 * node + c] < a ? x[3 * node + c] : a;
        b = x[3 * node + c] > b ? x[3 * node + c] : b;
      }
      h = b - a + 2.0 * reach[j] > h ? b - a + 2.0 * reach[j] : h;
    }
  /* Cubes of half that: a segment overlaps at most 3 of them each way, and tests about
   * half the nodes that cubes of the whole box would give it (bench/contact.py). */
  h *= 0.5;
  int64_t dims[3];
  for (;;)
  {
    double cells = 1.0;
    for (int c = 0; c < 3; ++c)
    {
      dims[c] = (int64_t)floor((high[c] - low[c]) / h) + 1;
      cells *= (double)dims[c];
    }
    if (cells <= 2.0 * (double)nsec + 8.0)
      break;
    h *= 1.5;
  }
  const int64_t buckets = dims[0] * dims[1] * dims[2];
  /* Counting sort of the secondary nodes into the buckets: start[b] .. start[b + 1]. */
  int64_t *bucket_of = work, *order = work + nsec;
  int64_t *start = (int64_t *)calloc(buckets + 1, sizeof(int64_t));
  for (int64_t i = 0; i < nsec; ++i)
  {
    int64_t b = 0;
    for (int c = 0; c < 3; ++c)
    {
      int64_t k = (int64_t)floor((x[3 * secondary[i] + c] - low[c]) / h);
      k = k < 0 ? 0 : (k >= dims[c] ? dims[c] - 1 : k);
      b = b * dims[c] + k;
    }
    bucket_of[i] = b;
    start[b + 1] += 1;
  }
  for (int64_t b = 0; b < buckets; ++b)
    start[b + 1] += start[b];
  int64_t *fill = (int64_t *)malloc((buckets + 1) * sizeof(int64_t));
  for (int64_t b = 0; b <= buckets; ++b)
    fill[b] = start[b];
  for (int64_t i = 0; i < nsec; ++i)
    order[fill[bucket_of[i]]++] = i;
  /* The nodes' positions in bucket order: a bucket's nodes are read from one stretch of
   * memory, wherever their rows are (the sort's time per node then holds on large meshes). */
  double *xb = (double *)malloc(3 * (nsec > 0 ? nsec : 1) * sizeof(double));
  for (int64_t m = 0; m < nsec; ++m)
    for (int c = 0; c < 3; ++c)
      xb[3 * m + c] = x[3 * secondary[order[m]] + c];
  /* The pairs (segment, node) in segment order, then sorted by node (stable). */
  int64_t *pair_node = work + 2 * nsec, *pair_seg = pair_node + capacity;
  int64_t count = 0;
  for (int64_t j = 0; j < nseg; ++j)
  {
    const int64_t *seg = segs + 4 * j;
    double a[3] = {INFINITY, INFINITY, INFINITY}, b[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < 4; ++k)
      if (seg[k] >= 0)
        for (int c = 0; c < 3; ++c)
        {
          const double xc = x[3 * seg[k] + c];
          a[c] = xc < a[c] ? xc : a[c];
          b[c] = xc > b[c] ? xc : b[c];
        }
    int64_t from[3], to[3];
    for (int c = 0; c < 3; ++c)
    {
      a[c] -= reach[j];
      b[c] += reach[j];
      from[c] = (int64_t)floor((a[c] - low[c]) / h);
      to[c] = (int64_t)floor((b[c] - low[c]) / h);
      from[c] = from[c] < 0 ? 0 : from[c];
      to[c] = to[c] >= dims[c] ? dims[c] - 1 : to[c];
    }
    for (int64_t p = from[0]; p <= to[0]; ++p)
      for (int64_t q = from[1]; q <= to[1]; ++q)
        for (int64_t r = from[2]; r <= to[2]; ++r)
        {
          const int64_t bucket = (p * dims[1] + q) * dims[2] + r;
          for (int64_t m = start[bucket]; m < start[bucket + 1]; ++m)
          {
            const double *xm = xb + 3 * m;
            int inside = 1;
            for (int c = 0; c < 3; ++c)
              inside &= xm[c] >= a[c] && xm[c] <= b[c];
            if (!inside)
              continue;
            const int64_t i = order[m], s = secondary[i];
            int own = 0;
            for (int k = 0; k < 4; ++k)
              own |= seg[k] == s;
            if (own)
              continue;
            if (removed && listed(s, removed + removed_offsets[j], removed + removed_offsets[j + 1]))
              continue;
            if (count < capacity)
            {
              pair_node[count] = i;
              pair_seg[count] = j;
            }
            ++count;
          }
        }
  }
  free(start);
  free(fill);
  free(xb);
  if (count > capacity)
    return count;
  for (int64_t k = 0; k < count; ++k)
    offsets[pair_node[k] + 1] += 1;
  for (int64_t i = 0; i < nsec; ++i)
    offsets[i + 1] += offsets[i];
  int64_t *next = work; /* nsec + 1 values: bucket_of and order are done with */
  for (int64_t i = 0; i <= nsec; ++i)
    next[i] = offsets[i];
  for (int64_t k = 0; k < count; ++k)
    candidates[next[pair_node[k]]++] = pair_seg[k];
  return count;
}

/* The closest point of triangle (a, b, c) to p as barycentric weights (Ericson, Real-Time
 * Collision Detection, 5.1.5). */
static void closest_on_triangle(const double p[3], const double a[3], const double b[3],
                                const double c[3], double w[3])
{
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  csub(b, a, ab);
  csub(c, a, ac);
  csub(p, a, ap);
  const double d1 = cdot(ab, ap), d2 = cdot(ac, ap);
  w[0] = 1.0, w[1] = 0.0, w[2] = 0.0;
  if (d1 <= 0.0 && d2 <= 0.0)
    return;
  csub(p, b, bp);
  const double d3 = cdot(ab, bp), d4 = cdot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3)
  {
    w[0] = 0.0, w[1] = 1.0;
    return;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
  {
    const double v = d1 / (d1 - d3);
    w[0] = 1.0 - v, w[1] = v;
    return;
  }
  csub(p, c, cp);
  const double d5 = cdot(ab, cp), d6 = cdot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6)
  {
    w[0] = 0.0, w[2] = 1.0;
    return;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
  {
    const double t = d2 / (d2 - d6);
    w[0] = 1.0 - t, w[2] = t;
    return;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
  {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[0] = 0.0, w[1] = 1.0 - t, w[2] = t;
    return;
  }
  const double denominator = va + vb + vc;
  if (!(denominator > 0.0)) /* a degenerate triangle: its first corner */
    return;
  const double v = vb / denominator, t = vc / denominator;
  w[0] = 1.0 - v - t, w[1] = v, w[2] = t;
}

/* The closest point q of segment `seg` to p, its weights on the segment's nodes (4), and
 * the segment's unit normal (outward); returns the distance of p to the segment (m: the
 * closest triangle's, a continuous function of p, which the blend below does not move). */
static double closest_on_segment(const double p[3], const int64_t *seg, const double *x,
                                 double q[3], double weights[4], double normal[3])
{
  const int corners = seg[3] >= 0 ? 4 : 3;
  const double *y[4];
  for (int k = 0; k < corners; ++k)
    y[k] = x + 3 * seg[k];
  double e1[3], e2[3];
  if (corners == 3)
  {
    csub(y[1], y[0], e1);
    csub(y[2], y[0], e2);
  }
  else
  {
    csub(y[2], y[0], e1);
    csub(y[3], y[1], e2);
  }
  ccross(e1, e2, normal);
  const double length = sqrt(cdot(normal, normal));
  for (int c = 0; c < 3; ++c)
    normal[c] = length > 0.0 ? normal[c] / length : 0.0;
  for (int k = 0; k < 4; ++k)
    weights[k] = 0.0;
  double nearest = 0.0;
  if (corners == 3)
  {
    closest_on_triangle(p, y[0], y[1], y[2], weights);
  }
  else
  {
    /* The closest of the 4 triangles about the centre. Where two of them are (nearly)
     * as close, as for a point over a diagonal of a warped quad, the closest point jumps
     * from one to the other (by the warp) as the point crosses: the weights of the
     * triangles within a band of 1e-7 of the distance of the closest are blended (shares
     * falling linearly from 1 to 0 over the band), so that the weights (and the forces)
     * stay continuous and round-off cannot pick one side or the other. On a flat quad the
     * blend moves the point toward a diagonal by at most sqrt(2e-7) of the distance (the
     * neighbour's distance grows with the square of the offset), so the direction of the
     * force turns by at most 4.5e-4 rad, within 4.5e-4 of the distance of a diagonal. */
    double centre[3], distance[4], w[4][3];
    for (int c = 0; c < 3; ++c)
      centre[c] = 0.25 * (((y[0][c] + y[1][c]) + y[2][c]) + y[3][c]);
    double best = INFINITY;
    for (int k = 0; k < 4; ++k)
    {
      const int l = (k + 1) % 4;
      double r[3];
      closest_on_triangle(p, centre, y[k], y[l], w[k]);
      for (int c = 0; c < 3; ++c)
        r[c] = p[c] - (w[k][0] * centre[c] + w[k][1] * y[k][c] + w[k][2] * y[l][c]);
      distance[k] = sqrt(cdot(r, r));
      best = distance[k] < best ? distance[k] : best;
    }
    const double band = 1e-7 * best;
    double total = 0.0;
    for (int k = 0; k < 4; ++k)
    {
      const double share = band > 0.0 ? 1.0 - (distance[k] - best) / band
                                       : (distance[k] == best ? 1.0 : 0.0);
      if (!(share > 0.0))
        continue;
      const int l = (k + 1) % 4;
      for (int m = 0; m < 4; ++m)
        weights[m] += share * 0.25 * w[k][0];
      weights[k] += share * w[k][1];
      weights[l] += share * w[k][2];
      total += share;
    }
    for (int m = 0; m < 4; ++m)
      weights[m] /= total;
    nearest = best;
  }
  for (int c = 0; c < 3; ++c)
  {
    q[c] = 0.0;
    for (int k = 0; k < corners; ++k)
      q[c] += weights[k] * y[k][c];
  }
  if (corners == 3)
  {
    double r[3];
    csub(p, q, r);
    return sqrt(cdot(r, r));
  }
  return nearest;
}

/* A segment of negative depth is a shell's mid-surface, both sides active: a node's
 * distance to it is unsigned and it is pushed out on the side it is on. */
INLINE int two_sided(double depth) { return depth < 0.0; }

/* The gap (m) of node s against a segment of depth `depth` and size share `size`: the
 * interface's, or with half_thickness (a variable gap, Radioss Igap 3) the node's half
 * thickness plus the segment's (-depth for a shell, 0 for a solid's face), at most the
 * node's size share plus the segment's (node_size[s] + size: %mesh_size x their shortest
 * sides) and gap_max, and at least the interface's gap (the floor, Gapmin), as i7cor3.F
 * bounds the pair: max(GAPMIN, min(GAP_S + GAP_M, GAP_S_L + GAP_M_L, GAPMAX)). */
INLINE double pair_gap(const contact_params *prm, int64_t s, double depth, double size)
{
  if (!prm->half_thickness)
    return prm->gap;
  double pair = prm->half_thickness[s] + (two_sided(depth) ? -depth : 0.0);
  const double sizes = (prm->node_size ? prm->node_size[s] : INFINITY) + size;
  pair = pair < sizes ? pair : sizes;
  pair = pair < prm->gap_max ? pair : prm->gap_max;
  return pair > prm->gap ? pair : prm->gap;
}

/* The normal force (N) of penetration p (m) for stiffness k0 (N/m) and gap g (m), its
 * tangent stiffness (N/m, into *tangent) and stored energy (J, into *energy):
 * f = -k0 g ln(1 - p/g) up to p = cap g, then on along its tangent there. */
static double penalty(double p, double k0, double g, double cap, double *tangent,
                      double *energy)
{
  const double x = p / g;
  if (x <= cap)
  {
    const double l = log1p(-x);
    *tangent = k0 / (1.0 - x);
    *energy = k0 * g * g * ((1.0 - x) * l + x);
    return -k0 * g * l;
  }
  const double l = log1p(-cap), kc = k0 / (1.0 - cap), beyond = p - cap * g;
  *tangent = kc;
  *energy = k0 * g * g * ((1.0 - cap) * l + cap) - k0 * g * l * beyond + 0.5 * kc * beyond * beyond;
  return -k0 * g * l + kc * beyond;
}

/* The closest point of a node on the surface: the segments within BAND of the closest
 * distance blended, their weights merged over their nodes. */
#define BAND 1e-7
#define BLEND_NODES 64
typedef struct
{
  int n;                        /* nodes in the blend */
  int64_t node[BLEND_NODES];    /* surface nodes */
  double weight[BLEND_NODES];   /* their shares of the point (sum 1) */
  double d;                     /* signed distance, m (< 0 behind the surface) */
  double normal[3];             /* unit, from the surface toward the node's side */
  double k0, depth;             /* the blended segments' stiffness (N/m) and depth (m) */
  double size;                  /* and size share (m, see pair_gap) */
} surface_point;

/* The boxes of the segments `used` (nused of them, indices into segs) at positions x: 6
 * values a segment in `boxes` (its corners' lowest x, y, z, then highest), the others'
 * left as they are.  Once a list, so that each candidate's test reads one row. */
static void segment_boxes(int64_t nused, const int64_t *restrict used,
                          const int64_t *restrict segs, const double *restrict x,
                          double *restrict boxes)
{
  for (int64_t u = 0; u < nused; ++u)
  {
    const int64_t j = used[u], *seg = segs + 4 * j;
    const int corners = seg[3] >= 0 ? 4 : 3;
    double *box = boxes + 6 * j;
    for (int c = 0; c < 3; ++c)
    {
      double a = x[3 * seg[0] + c], b = a;
      for (int k = 1; k < corners; ++k)
      {
        const double y = x[3 * seg[k] + c];
        a = y < a ? y : a;
        b = y > b ? y : b;
      }
      box[c] = a;
      box[3 + c] = b;
    }
  }
}

/* A segment's closest point to a node (closest_on_segment): distance (m, INFINITY when not
 * sought), point, weights and normal. */
typedef struct
{
  double d, q[3], w[4], n[3];
} segment_point;

/* The squared distance (m^2) of p to a segment's box (segment_boxes): a lower bound of its
 * distance to the segment (which lies in the box).  At most one of the two terms of an
 * axis is positive (low <= high), so each is the distance along it, without a branch. */
INLINE double box_distance2(const double p[3], const double *restrict box)
{
  double d2 = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    const double below = box[c] - p[c], above = p[c] - box[3 + c];
    const double out = (below > 0.0 ? below : 0.0) + (above > 0.0 ? above : 0.0);
    d2 += out * out;
  }
  return d2;
}

/* A candidate farther than FAR reach from the node is skipped: its distance d is then
 * beyond the reach (it cannot be the closest) and beyond the band of any closest
 * distance below the reach (d - best > 1e-6 reach > BAND best: its share would be < 0),
 * with room for the round-off of both distances, so that skipping it changes nothing. */
#define FAR (1.0 + 1e-6)

/* The squared distance (m^2) of p to segment s-e, LANES pairs at once. */
INLINE vec edge_distance2(const vec p[3], const vec s[3], const vec e[3])
{
  vec d[3], r[3];
  for (int c = 0; c < 3; ++c)
  {
    d[c] = e[c] - s[c];
    r[c] = p[c] - s[c];
  }
  const vec t = vmin(vmax(dot3(r, d) / vmax(dot3(d, d), VZERO + 1e-300), VZERO), VZERO + 1.0);
  for (int c = 0; c < 3; ++c)
    r[c] -= t * d[c];
  return dot3(r, r);
}

/* The squared distance (m^2) of p to the segment of corners y (a quadrilateral's 4
 * triangles about its centre, a triangle's 3 corners with the 3rd again as 4th), LANES
 * pairs at once and without a branch: the least of the distances to the triangles' edges
 * and, where p projects inside a triangle (on the inner side of its 3 edges), to its
 * plane.  It is closest_on_segment's distance (squared) to round-off (a relative 1e-13;
 * a triangle as a quadrilateral is the same 3 triangles about a point inside it and one
 * of no area), at a fifth of its time on 4 lanes (closest_on_segment's branches, per
 * region of each triangle, are taken at random across the pairs). */
INLINE vec segment_distance2(const vec p[3], const vec y[4][3])
{
  vec centre[3], r[3], s[4][3];
  for (int c = 0; c < 3; ++c)
  {
    centre[c] = 0.25 * (((y[0][c] + y[1][c]) + y[2][c]) + y[3][c]);
    r[c] = p[c] - centre[c];
    for (int k = 0; k < 4; ++k)
      s[k][c] = y[k][c] - centre[c];
  }
  vec best = VZERO + INFINITY;
  for (int k = 0; k < 4; ++k)
  {
    const int l = (k + 1) % 4;
    best = vmin(best, vmin(edge_distance2(p, centre, y[k]), edge_distance2(p, y[k], y[l])));
    vec normal[3], rim[3], from_k[3], t[3];
    cross(s[k], s[l], normal);
    for (int c = 0; c < 3; ++c)
    {
      rim[c] = s[l][c] - s[k][c];
      from_k[c] = r[c] - s[k][c];
    }
    cross(s[k], r, t);
    const vec u0 = dot3(t, normal);
    cross(rim, from_k, t);
    const vec u1 = dot3(t, normal);
    cross(r, s[l], t);
    const vec u2 = dot3(t, normal);
    const vec area2 = dot3(normal, normal), h = dot3(r, normal);
    const ivec inside = (u0 >= 0.0) & (u1 >= 0.0) & (u2 >= 0.0) & (area2 > 0.0);
    best = vmin(best, vselect(inside, h * h / vmax(area2, VZERO + 1e-300), VZERO + INFINITY));
  }
  return best;
}

/* segment_distance2 of the first n pairs of the LANES in p, y into d2[pair[0 .. n)] (the
 * lanes from n on get the first pair again). */
INLINE void batch_distances(vec p[3], vec y[4][3], const int64_t *restrict pair, int n,
                            double *restrict d2)
{
  for (int m = n; m < LANES; ++m)
    for (int c = 0; c < 3; ++c)
    {
      p[c][m] = p[c][0];
      for (int l = 0; l < 4; ++l)
        y[l][c][m] = y[l][c][0];
    }
  const vec found = segment_distance2(p, y);
  for (int m = 0; m < n; ++m)
    d2[pair[m]] = found[m];
}

/* The squared distances d2 (m^2) of the nsec secondary nodes to their candidates
 * candidates[offsets[0] .. offsets[nsec]) (d2 indexed as the candidates) at positions x,
 * segment_distance2's, LANES pairs at a time, but INFINITY for a candidate surely farther
 * than `far` (m): its box (`boxes`, segment_boxes, unless NULL) is, or its distance at the
 * near lists (`listed`, m, per candidate, unless NULL) was farther than far + slack (m).
 * NaN positions give NaN, never INFINITY. */
static void candidate_distances(int64_t nsec, const int64_t *restrict secondary,
                                const int64_t *restrict offsets,
                                const int64_t *restrict candidates,
                                const int64_t *restrict segs, const double *restrict x,
                                const double *restrict boxes, const double *restrict listed,
                                double slack, double far, double *restrict d2)
{
  const double far2 = far * far, beyond = far + slack;
  vec p[3], y[4][3];
  int64_t pair[LANES];
  int n = 0;
  for (int64_t i = 0; i < nsec; ++i)
  {
    const double *xs = x + 3 * secondary[i];
    for (int64_t k = offsets[i]; k < offsets[i + 1]; ++k)
    {
      const int64_t *seg = segs + 4 * candidates[k];
      if ((listed && listed[k] > beyond) ||
          (boxes && box_distance2(xs, boxes + 6 * candidates[k]) > far2))
      {
        d2[k] = INFINITY;
        continue;
      }
      for (int c = 0; c < 3; ++c)
      {
        p[c][n] = xs[c];
        for (int m = 0; m < 4; ++m) /* a triangle's 3rd corner again as its 4th */
          y[m][c][n] = x[3 * seg[seg[3] >= 0 || m < 3 ? m : 2] + c];
      }
      pair[n++] = k;
      if (n == LANES)
      {
        batch_distances(p, y, pair, n, d2);
        n = 0;
      }
    }
  }
  if (n > 0)
    batch_distances(p, y, pair, n, d2);
}

/* The near list: of the candidates of the nsec secondary nodes (offsets, candidates, from
 * the sort), those within `limit` (m) of their node at positions x, into near_offsets
 * (nsec + 1), near (in the candidates' order) and near_distance (their distances, m; both
 * as long as the candidates); the
 * boxes of the nused segments `used` (all the candidates') into `boxes`, which rule out
 * most candidates first.  A node and every point of a segment (a weighted mean of its
 * corners) having moved at most r since, the node's distance to the segment has changed
 * by at most 2 r: while no node has moved more than (limit - FAR reach) / 2, a candidate
 * left out stays farther than FAR reach, and the pass over the list skips exactly what it
 * would skip over the candidates (ContactInterface, the skin).  Returns the length of the
 * list. */
int64_t contact_near(int64_t nsec, const int64_t *restrict secondary,
                     const int64_t *restrict offsets, const int64_t *restrict candidates,
                     const int64_t *restrict segs, int64_t nused, const int64_t *restrict used,
                     double *restrict boxes, const double *restrict x, double limit,
                     int64_t *restrict near_offsets, int64_t *restrict near,
                     double *restrict near_distance)
{
  segment_boxes(nused, used, segs, x, boxes);
  /* the squared distances into near_distance (as long as the candidates), then the list
   * packed in place (count <= k) */
  candidate_distances(nsec, secondary, offsets, candidates, segs, x, boxes, NULL, 0.0, limit,
                      near_distance);
  const double limit2 = limit * limit;
  int64_t count = 0;
  near_offsets[0] = 0;
  for (int64_t i = 0; i < nsec; ++i)
  {
    for (int64_t k = offsets[i]; k < offsets[i + 1]; ++k)
      if (!(near_distance[k] > limit2)) /* NaN stays */
      {
        near[count] = candidates[k];
        near_distance[count++] = sqrt(near_distance[k]);
      }
    near_offsets[i + 1] = count;
  }
  return count;
}

/* The closest point of node xs among candidates[from..to) (within `reach`, m), into *pt;
 * 0 if none is within reach.  `d2` are the candidates' squared distances
 * (candidate_distances, indexed as the candidates); `near` holds to - from closest points
 * (scratch).
 *
 * The segments whose distance is within BAND of the closest one's share the point, in
 * shares falling linearly from 1 to 0 over that band, as the triangles of a quadrilateral
 * do (closest_on_segment): a node facing the common edge or corner of several segments
 * is then a continuous function of its position, which round-off cannot decide (the
 * forces do not depend on the order of the segments, hence on the partition).  The side
 * of the surface the node is on is the sign of the blended r . n (r from each segment's
 * closest point to the node, n its normal): at an edge or a corner, where the tied
 * segments' closest points meet, that is r . (n_1 + n_2 + ...), the pseudo-normal test
 * (Baerentzen and Aanaes 2005), so that a node beside a face, beyond the edge it shares
 * with the face the node is in front of, is not taken as behind the first one's plane.
 * The distance is the closest one's (continuous); the direction is from the blended point. */
static int closest_on_surface(const double xs[3], int64_t from, int64_t to,
                              const int64_t *restrict candidates, const int64_t *restrict segs,
                              const double *restrict stiffness0, const double *restrict depth,
                              const double *restrict size, const double *restrict x,
                              const double *restrict d2,
                              double reach, segment_point *restrict near, surface_point *pt)
{
  double best = INFINITY;
  const double far2 = FAR * reach * FAR * reach;
  for (int64_t k = from; k < to; ++k)
  {
    const int64_t j = candidates[k];
    segment_point *sp = near + (k - from);
    if (d2[k] > far2)
    {
      sp->d = INFINITY; /* out of reach and out of any band: as the exact distance would be
                           (see FAR) */
      continue;
    }
    sp->d = closest_on_segment(xs, segs + 4 * j, x, sp->q, sp->w, sp->n);
    best = sp->d < reach && sp->d < best ? sp->d : best; /* NaN is out of reach */
  }
  if (!(best < reach))
    return 0;
  const double band = BAND * best;
  double total = 0.0, along = 0.0, q_sum[3] = {0.0, 0.0, 0.0}, n_sum[3] = {0.0, 0.0, 0.0};
  pt->n = 0;
  pt->k0 = pt->depth = pt->size = 0.0;
  for (int64_t k = from; k < to; ++k)
  {
    const segment_point *sp = near + (k - from);
    const double dk = sp->d;
    const double share = band > 0.0 ? 1.0 - (dk - best) / band : (dk == best ? 1.0 : 0.0);
    if (!(share > 0.0))
      continue;
    const int64_t j = candidates[k], *seg = segs + 4 * j;
    const double *q = sp->q, *w = sp->w, *n = sp->n;
    double r[3];
    csub(xs, q, r);
    along += share * cdot(r, n);
    for (int c = 0; c < 3; ++c)
    {
      q_sum[c] += share * q[c];
      n_sum[c] += share * n[c];
    }
    pt->k0 += share * stiffness0[j];
    pt->depth += share * depth[j];
    pt->size += share * (size ? size[j] : INFINITY);
    total += share;
    for (int m = 0; m < 4; ++m)
    {
      if (seg[m] < 0 || w[m] == 0.0)
        continue;
      int at = 0;
      while (at < pt->n && pt->node[at] != seg[m])
        ++at;
      if (at == pt->n)
      {
        if (pt->n == BLEND_NODES) /* not met on a surface mesh: the rest is left out */
          continue;
        pt->node[pt->n] = seg[m];
        pt->weight[pt->n++] = 0.0;
      }
      pt->weight[at] += share * w[m];
    }
  }
  double weights = 0.0;
  for (int m = 0; m < pt->n; ++m)
    weights += pt->weight[m];
  for (int m = 0; m < pt->n; ++m)
    pt->weight[m] /= weights;
  pt->k0 /= total;
  pt->depth /= total;
  pt->size /= total;
  pt->d = along >= 0.0 || two_sided(pt->depth) ? best : -best;
  double r[3];
  for (int c = 0; c < 3; ++c)
    r[c] = xs[c] - q_sum[c] / total;
  const double length = sqrt(cdot(r, r));
  const double side = pt->d >= 0.0 ? 1.0 : -1.0;
  if (length > 1e-9 * reach)
    for (int c = 0; c < 3; ++c)
      pt->normal[c] = side * r[c] / length;
  else /* on the surface: the segments' normal */
  {
    const double size = sqrt(cdot(n_sum, n_sum));
    for (int c = 0; c < 3; ++c)
      pt->normal[c] = size > 0.0 ? n_sum[c] / size : 0.0;
  }
  return 1;
}

/* A model cut by symmetry planes: a secondary node s on such planes meets, in the whole
 * model, its segment and the segment's mirror images at one distance; their blend puts the
 * point on the planes, so the normal lies in them: its components normal to the planes go.
 * The node holds share[s] of the whole node's mass (1/2 on a plane, 1/4 on two), so its
 * pair takes that share of the whole pair's stiffness (hence of its force, energy and
 * friction); the damping sees the whole nodes' masses, mass / share; the velocity
 * relative to the point loses its components normal to the planes, as the blend of the
 * mirror images averages them away. */
INLINE double mirror(const contact_params *prm, int64_t s, surface_point *pt)
{
  if (!prm->share)
    return 1.0;
  const int8_t planes = prm->planes[s];
  if (planes)
  {
    double size = 0.0;
    for (int c = 0; c < 3; ++c)
    {
      pt->normal[c] = (planes >> c) & 1 ? 0.0 : pt->normal[c];
      size += pt->normal[c] * pt->normal[c];
    }
    size = sqrt(size);
    for (int c = 0; c < 3; ++c)
      pt->normal[c] = size > 0.0 ? pt->normal[c] / size : 0.0;
  }
  return prm->share[s];
}

/* What a pass over the candidates of the nsec secondary nodes (positions x) finds first:
 * the candidates' squared distances within FAR reach (candidate_distances, with their
 * distances at the near lists `listed` unless NULL, nodes having moved at most `moved` (m)
 * since; returned: the caller frees it) and room for the closest points of a node's
 * candidates (*near: the caller frees it). */
static double *pass_scratch(int64_t nsec, const int64_t *restrict secondary,
                            const int64_t *restrict offsets, const int64_t *restrict candidates,
                            const double *restrict listed, double moved,
                            const int64_t *restrict segs, const double *restrict x,
                            double reach, segment_point **near)
{
  int64_t most = 1;
  for (int64_t i = 0; i < nsec; ++i)
    most = offsets[i + 1] - offsets[i] > most ? offsets[i + 1] - offsets[i] : most;
  *near = (segment_point *)malloc(most * sizeof(segment_point));
  double *d2 = (double *)malloc((offsets[nsec] + 1) * sizeof(double));
  candidate_distances(nsec, secondary, offsets, candidates, segs, x, NULL, listed, 2.0 * moved,
                      FAR * reach, d2);
  return d2;
}

/* Nodes that start inside the gap (Radioss TYPE7 Inacti = 6): a node at distance d0 < gap
 * from the surface at the start gets its own gap 0.95 d0 (Radioss: gap0 = Gap - P0 - 5 %
 * of (Gap - P0), P0 = Gap - d0 the initial penetration), so that it is not pushed out at
 * once; the gap grows back with the node's distance (0.95 d, up to the interface's gap)
 * as it moves away, and never shrinks.  A node that starts behind the surface (d0 <= 0)
 * gets gap 0: inactive until it comes out in front. */
#define INITIAL_GAP 0.95

/* The node's gap (m) at its signed distance d (m), against the pair's gap `gap`: *node_gap
 * (INFINITY for a node that did not start inside) grows with 0.95 d and is dropped
 * (INFINITY) once it reaches `gap`; it never shrinks. */
INLINE double grown_gap(double *node_gap, double d, double gap)
{
  if (*node_gap < gap)
  {
    const double grown = INITIAL_GAP * d;
    *node_gap = grown >= gap ? INFINITY : (grown > *node_gap ? grown : *node_gap);
  }
  return *node_gap < gap ? *node_gap : gap;
}

/* The gaps of the nsec secondary nodes at the start (node_gap, m), as above. out: [0] the
 * number of nodes that start inside the gap, [1] of them behind the surface, [2] the
 * largest initial penetration gap - d0 (m). */
void contact_initial_gaps(int64_t nsec, const int64_t *restrict secondary,
                          const int64_t *restrict offsets, const int64_t *restrict candidates,
                          const int64_t *restrict segs, const double *restrict stiffness0,
                          const double *restrict depth, const double *restrict size,
                          const double *restrict x, const contact_params *prm,
                          double *restrict node_gap, double out[3])
{
  out[0] = out[1] = out[2] = 0.0;
  segment_point *near;
  double *d2 = pass_scratch(nsec, secondary, offsets, candidates, NULL, 0.0, segs, x,
                            prm->reach, &near);
  surface_point pt;
  for (int64_t i = 0; i < nsec; ++i)
  {
    node_gap[i] = INFINITY;
    if (!closest_on_surface(x + 3 * secondary[i], offsets[i], offsets[i + 1], candidates,
                            segs, stiffness0, depth, size, x, d2, prm->reach, near, &pt))
      continue;
    const double g = pair_gap(prm, secondary[i], pt.depth, pt.size);
    if (!(pt.d < g && (two_sided(pt.depth) || -pt.d < pt.depth)))
      continue;
    node_gap[i] = pt.d > 0.0 ? INITIAL_GAP * pt.d : 0.0;
    out[0] += 1.0;
    out[1] += pt.d > 0.0 ? 0.0 : 1.0;
    out[2] = g - pt.d > out[2] ? g - pt.d : out[2];
  }
  free(near);
  free(d2);
}

/* One pass: the nsec secondary nodes against their candidate segments, with `listed` their
 * distances at the near lists (m, contact_near, nodes having moved at most prm->moved
 * since), or NULL: all of them sought.  `stiffness0`,
 * `depth` (m: how deep behind a segment a node is still pushed out) and `size` (m, the
 * segment's size share of a variable gap, pair_gap; NULL: none) are per segment;
 * `tangential` (nsec rows) is each secondary node's friction force of the previous step
 * (N), updated; `node_gap` each node's gap (m, contact_initial_gaps), grown as it leaves.
 * out: [0..2] the force on the secondary nodes (N), [3..5] its tangential
 * part, [6] the number of nodes in contact, [7] the stored normal energy (J), [8] the
 * tangential springs' energy (J), [9] what friction and damping dissipated over the step (J),
 * [10] the sum of the normal forces' sizes (N). */
void contact_forces(int64_t nsec, const int64_t *restrict secondary,
                    const int64_t *restrict offsets, const int64_t *restrict candidates,
                    const double *restrict listed, const int64_t *restrict segs,
                    const double *restrict stiffness0,
                    const double *restrict depth, const double *restrict size,
                    const double *restrict x, const double *restrict v,
                    const double *restrict mass,
                    const contact_params *prm,
                    double *restrict tangential, double *restrict node_gap,
                    double *restrict force, double *restrict stiffness, double out[11])
{
  for (int c = 0; c < 11; ++c)
    out[c] = 0.0;
  segment_point *near;
  double *d2 = pass_scratch(nsec, secondary, offsets, candidates, listed, prm->moved, segs, x,
                            prm->reach, &near);
  surface_point pt;
  for (int64_t i = 0; i < nsec; ++i)
  {
    const int64_t s = secondary[i];
    const double *xs = x + 3 * s;
    double *ft = tangential + 3 * i;
    /* (a node without candidates, most of them, has no closest point: not looked for) */
    if (offsets[i] == offsets[i + 1] ||
        !closest_on_surface(xs, offsets[i], offsets[i + 1], candidates, segs, stiffness0,
                            depth, size, x, d2, prm->reach, near, &pt))
    {
      ft[0] = ft[1] = ft[2] = 0.0;
      node_gap[i] = INFINITY;
      continue;
    }
    const double g = grown_gap(node_gap + i, pt.d, pair_gap(prm, s, pt.depth, pt.size));
    const double share = mirror(prm, s, &pt);
    const double k0 = share * pt.k0;
    if (!(g > 0.0 && pt.d < g && (two_sided(pt.depth) || -pt.d < pt.depth)))
    {
      /* Near but not in contact: its spring's stiffness counts in the step all the same,
       * so that the step does not jump as nodes come into and out of contact. */
      stiffness[s] += k0;
      for (int m = 0; m < pt.n; ++m)
        stiffness[pt.node[m]] += pt.weight[m] * k0;
      ft[0] = ft[1] = ft[2] = 0.0;
      continue;
    }
    double kt, energy;
    const double spring = penalty(g - pt.d, k0, g, prm->cap, &kt, &energy);
    /* The velocity relative to the segment's point, and the normal damping of the pair
     * (masses m_s and sum w_i m_i): c = 2 damping sqrt(kt m_s m_main / (m_s + m_main)),
     * its force bounded by the spring's: the normal force starts at 0 as a node comes
     * into contact (no jump for round-off to decide) and never pulls. */
    double w[3];
    double main_mass = 0.0;
    for (int c = 0; c < 3; ++c)
      w[c] = v[3 * s + c];
    for (int m = 0; m < pt.n; ++m)
    {
      main_mass += pt.weight[m] * mass[pt.node[m]] / (prm->share ? prm->share[pt.node[m]] : 1.0);
      for (int c = 0; c < 3; ++c)
        w[c] -= pt.weight[m] * v[3 * pt.node[m] + c];
    }
    if (prm->planes) /* the whole model's blend: the mirror images' velocities averaged */
      for (int c = 0; c < 3; ++c)
        w[c] = (prm->planes[s] >> c) & 1 ? 0.0 : w[c];
    const double *normal = pt.normal;
    const double wn = cdot(w, normal);
    const double whole = mass[s] / share; /* the whole node's */
    const double reduced = share * whole * main_mass / (whole + main_mass);
    const double viscous = 2.0 * prm->damping * sqrt(kt * reduced);
    double damper = -viscous * wn;
    damper = damper > spring ? spring : (damper < -spring ? -spring : damper);
    const double fn = spring + damper;
    out[9] += (spring - fn) * wn * prm->dt; /* what the damping took over the step */
    double f[3];
    for (int c = 0; c < 3; ++c)
      f[c] = fn * normal[c];
    if (prm->friction > 0.0)
    {
      /* The tangential relative velocity, and the elastic trial force. */
      double old[3], trial[3];
      const double on = cdot(ft, normal);
      for (int c = 0; c < 3; ++c)
      {
        w[c] -= wn * normal[c];
        old[c] = ft[c] - on * normal[c];
        trial[c] = old[c] - k0 * prm->dt * w[c];
      }
      coulomb_law(trial, prm->alpha < 1.0 ? old : NULL, prm->alpha, prm->friction * fn);
      double slip = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        slip += trial[c] * (w[c] * prm->dt + (trial[c] - old[c]) / k0);
        ft[c] = trial[c];
        f[c] += trial[c];
        out[3 + c] += trial[c];
      }
      out[8] += 0.5 * cdot(trial, trial) / k0;
      out[9] -= slip;
    }
    for (int c = 0; c < 3; ++c)
    {
      force[3 * s + c] += f[c];
      out[c] += f[c];
    }
    stiffness[s] += kt;
    for (int m = 0; m < pt.n; ++m)
    {
      for (int c = 0; c < 3; ++c)
        force[3 * pt.node[m] + c] -= pt.weight[m] * f[c];
      stiffness[pt.node[m]] += pt.weight[m] * kt;
    }
    out[6] += 1.0;
    out[7] += energy;
    out[10] += fn;
  }
  free(near);
  free(d2);
}

/* Whether the force f (N) on a node of velocity v (m/s) counts in a sum of f . v: not when
 * f is 0 (+0 or -0) and v finite, whose terms (+0 or -0) change no sum that starts at +0
 * (such a sum is never -0: x + (-x) is +0), so that the sums skip most surface nodes, out
 * of contact, yet come out the same to the bit. */
INLINE int counts(const double f[3], const double v[3])
{
  return f[0] != 0.0 || f[1] != 0.0 || f[2] != 0.0 ||
         !(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]));
}

/* One sweep of the rank's n owned surface nodes (the first local ones) before the passes:
 * the rows `rows` of the state into their x = X + u (m), vs (m/s) and ms (kg), and, unless
 * `packed` is NULL (one rank: nothing to send), packed 7 values a node for the other ranks;
 * unless NULL, out[0] = sum kept . v (W) of the forces `kept` (n rows, N) at the velocities
 * read (contact_power's sum, in its order), out[1] the largest squared distance (m^2) a
 * node moved since `sorted` (its positions at the latest sort), out[2] since `listed` (at
 * the latest near lists; the first n rows), each as contact_moved finds it (NaN once some
 * is NaN). */
void contact_read(int64_t n, const int64_t *restrict rows, const double *restrict X,
                  const double *restrict u, const double *restrict v,
                  const double *restrict mass, double *restrict packed, double *restrict x,
                  double *restrict vs, double *restrict ms, const double *restrict kept,
                  const double *restrict sorted, const double *restrict listed, double out[3])
{
  double power = 0.0, moved = 0.0, moved_listed = 0.0;
  for (int64_t i = 0; i < n; ++i)
  {
    const int64_t r = rows[i];
    double *xi = x + 3 * i;
    for (int c = 0; c < 3; ++c)
    {
      xi[c] = X[3 * r + c] + u[3 * r + c];
      vs[3 * i + c] = v[3 * r + c];
    }
    ms[i] = mass[r];
    if (packed)
    {
      double *p = packed + 7 * i;
      for (int c = 0; c < 3; ++c)
      {
        p[c] = xi[c];
        p[3 + c] = vs[3 * i + c];
      }
      p[6] = ms[i];
    }
    if (kept && counts(kept + 3 * i, v + 3 * r))
      for (int c = 0; c < 3; ++c)
        power += kept[3 * i + c] * v[3 * r + c];
    if (sorted)
      moved = farther(moved, xi, sorted + 3 * i);
    if (listed)
      moved_listed = farther(moved_listed, xi, listed + 3 * i);
  }
  out[0] = power;
  out[1] = moved;
  out[2] = moved_listed;
}

/* Packed rows to the surface nodes `order` (their positions, velocities and masses). */
void contact_unpack(int64_t n, const int64_t *restrict order, const double *restrict packed,
                    double *restrict x, double *restrict v, double *restrict mass)
{
  for (int64_t i = 0; i < n; ++i)
  {
    const int64_t k = order[i];
    const double *p = packed + 7 * i;
    for (int c = 0; c < 3; ++c)
    {
      x[3 * k + c] = p[c];
      v[3 * k + c] = p[3 + c];
    }
    mass[k] = p[6];
  }
}

/* One sweep of the rank's n owned surface nodes (the first local ones) after the passes:
 * add their forces `force` (N) to the accelerations of the state's rows `rows` (masses
 * `mass`), keep them in `kept`, and zero `force` and the contact stiffness `stiffness` (N/m)
 * for the next step.  out[0] = sum f . v (W) at the state's velocities v, out[1] the nodal
 * stable step over the nodes with k > 0 (s; inf: none), ms being the surface nodes' masses
 * (kg): sqrt(ms / (e + k / 2)), e = element[row] (N/m, the cells' sum m_c / dt_e^2 at the
 * node, step.h's note_steps; 0 when `element` is NULL: sqrt(2 ms / k), the springs alone). */
void contact_apply(int64_t n, const int64_t *restrict rows, double *restrict force,
                   double *restrict stiffness, const double *restrict ms,
                   const double *restrict mass, const double *restrict v, double *restrict a,
                   double *restrict kept, const double *restrict element, double out[2])
{
  double power = 0.0, smallest = INFINITY;
  for (int64_t i = 0; i < n; ++i)
  {
    const int64_t r = rows[i];
    double *f = force + 3 * i;
    if (counts(f, v + 3 * r) || !(mass[r] > 0.0))
      for (int c = 0; c < 3; ++c)
      {
        a[3 * r + c] += f[c] / mass[r];
        power += f[c] * v[3 * r + c];
      }
    else /* no term of the power (see counts), and f / m is f, +0 or -0 */
      for (int c = 0; c < 3; ++c)
        a[3 * r + c] += f[c];
    for (int c = 0; c < 3; ++c)
    {
      kept[3 * i + c] = f[c];
      f[c] = 0.0;
    }
    if (stiffness[i] > 0.0)
    {
      const double e = element ? element[r] : 0.0;
      const double dt = sqrt(ms[i] / (e + 0.5 * stiffness[i]));
      smallest = dt < smallest ? dt : smallest;
    }
    stiffness[i] = 0.0;
  }
  out[0] = power;
  out[1] = smallest;
}

/* sum f . v (W) of the kept forces (n rows) at the state's rows `rows`. */
double contact_power(int64_t n, const int64_t *restrict rows, const double *restrict kept,
                     const double *restrict v)
{
  double power = 0.0;
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      power += kept[3 * i + c] * v[3 * rows[i] + c];
  return power;
}
