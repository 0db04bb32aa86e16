/* The nodes each segment of a contact pass leaves out of its search (Radioss TYPE7
 * Irem_gap 2; OpenRadioss starter/source/interfaces/inter3d1/get_list_remnode.F90 and
 * i7remnode.F, applied in the sort as engine/.../intsort/i7trivox.F does; docs/theory.md,
 * "Nodes near a segment along the mesh").  Built once, from the positions at the start.
 *
 * For each segment i, a walk over the segments that hold a secondary node, ring after ring
 * through their shared nodes, gives each secondary node l it reaches a distance along the
 * mesh: 0 at the nodes of i, and from a node a of a segment of the previous ring to a node l
 * of a segment at a, dist(a) + |x_l - x_a| (sides and diagonals of the segments), the
 * least found.  The walk stops once the closest node reached in a ring is farther than
 * dmax less the shortest side of the pass (minseg): dmax = sqrt 2 x the gap (constant), or
 * sqrt 2 x min(g_m + max g_s, l_m + max l_s) (variable: the segment's thickness share g_m
 * and size share l_m, the largest of the secondary nodes').  Node l is left out of i's
 * search when its distance is at most sqrt 2 x the gap (constant), or sqrt 2 x its pair gap
 * with i, max(gap, min(g_s + g_m, l_s + l_m, gap_max)) (variable).  The nodes of i itself
 * are not listed (the sort leaves them out anyway).
 *
 * The walk visits the segments in their order in the pass and the nodes in their order in
 * the segments, as OpenRadioss does in its own; each segment's walk starts afresh (in
 * OpenRadioss a segment whose walk stops at once, minseg > dmax, leaves its nodes tagged
 * for the next segments of the same thread).  Each list comes sorted. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

static int remove_corners(const int64_t *seg) { return seg[3] >= 0 && seg[3] != seg[2] ? 4 : 3; }

static int remove_order(const void *a, const void *b)
{
  const int64_t p = *(const int64_t *)a, q = *(const int64_t *)b;
  return (p > q) - (p < q);
}

static inline double mesh_distance(const double *x, int64_t a, int64_t b)
{
  const double dx = x[3 * a] - x[3 * b], dy = x[3 * a + 1] - x[3 * b + 1],
               dz = x[3 * a + 2] - x[3 * b + 2];
  return sqrt(dx * dx + dy * dy + dz * dz);
}

/* The lists of the nseg segments `segs` (4 node indices each, -1 as a triangle's 4th) over
 * nnodes nodes at positions x (rows of 3, m); `secondary` tags the pass's secondary nodes.
 * seg_gap, seg_size (per segment) and node_gap, node_size (per node) are the thickness and
 * size shares of a variable gap (m; with `variable`), `gap` the constant gap or the floor
 * of the variable one, gap_max its bound (m).  Fills offsets (nseg + 1) and up to
 * `capacity` node indices into `removed`; returns how many there are (more than capacity:
 * call again with room). */
int64_t contact_remove_lists(int64_t nseg, const int64_t *restrict segs, int64_t nnodes,
                             const double *restrict x, const int8_t *restrict secondary,
                             const double *restrict seg_gap, const double *restrict seg_size,
                             const double *restrict node_gap, const double *restrict node_size,
                             int variable, double gap, double gap_max, int64_t capacity,
                             int64_t *restrict offsets, int64_t *restrict removed)
{
  offsets[0] = 0;
  /* The segments at each node, of those holding a secondary node (i7remnode_init). */
  int64_t *at = (int64_t *)calloc(nnodes + 1, sizeof(int64_t));
  int64_t *at_segs = (int64_t *)malloc((4 * nseg + 1) * sizeof(int64_t));
  double minseg = INFINITY, gaps_mx = 0.0, gaps_l_mx = 0.0;
  for (int64_t i = 0; i < nseg; ++i)
  {
    const int64_t *seg = segs + 4 * i;
    const int n = remove_corners(seg);
    int held = 0;
    for (int k = 0; k < n; ++k)
    {
      held |= secondary[seg[k]] != 0;
      const double side = mesh_distance(x, seg[k], seg[(k + 1) % n]);
      minseg = side < minseg ? side : minseg;
    }
    if (held)
      for (int k = 0; k < n; ++k)
        at[seg[k] + 1] += 1;
  }
  for (int64_t a = 0; a < nnodes; ++a)
  {
    at[a + 1] += at[a];
    if (secondary[a] && variable)
    {
      gaps_mx = node_gap[a] > gaps_mx ? node_gap[a] : gaps_mx;
      gaps_l_mx = node_size[a] > gaps_l_mx ? node_size[a] : gaps_l_mx;
    }
  }
  int64_t *fill = (int64_t *)malloc((nnodes + 1) * sizeof(int64_t));
  for (int64_t a = 0; a <= nnodes; ++a)
    fill[a] = at[a];
  for (int64_t i = 0; i < nseg; ++i)
  {
    const int64_t *seg = segs + 4 * i;
    const int n = remove_corners(seg);
    int held = 0;
    for (int k = 0; k < n; ++k)
      held |= secondary[seg[k]] != 0;
    if (held)
      for (int k = 0; k < n; ++k)
        at_segs[fill[seg[k]]++] = i;
  }
  free(fill);
  /* The walk's state: per node its distance, tag (0 not reached, 1 reached, 2 a node of
   * the segment being expanded), whether it was expanded in this ring and its pair gap;
   * per segment the ring it joined (0: none). */
  double *dist = (double *)malloc((nnodes + 1) * sizeof(double));
  double *gapv = (double *)calloc(nnodes + 1, sizeof(double));
  int8_t *tag = (int8_t *)calloc(nnodes + 1, 1), *expanded = (int8_t *)calloc(nnodes + 1, 1);
  int64_t *ring = (int64_t *)calloc(nseg + 1, sizeof(int64_t));
  int64_t *list = (int64_t *)malloc((nseg + 1) * sizeof(int64_t));
  int64_t *next = (int64_t *)malloc((nseg + 1) * sizeof(int64_t));
  int64_t *walked = (int64_t *)malloc((nseg + 1) * sizeof(int64_t));
  int64_t *reached = (int64_t *)malloc((nnodes + 1) * sizeof(int64_t));
  for (int64_t a = 0; a < nnodes; ++a)
    dist[a] = INFINITY;
  const double root2 = sqrt(2.0);
  int64_t count = 0;
  for (int64_t i = 0; i < nseg; ++i)
  {
    const int64_t *own = segs + 4 * i;
    const int n_own = remove_corners(own);
    const double dmax = variable ? root2 * fmin(seg_gap[i] + gaps_mx, seg_size[i] + gaps_l_mx)
                                 : root2 * gap;
    int64_t level = 1, nlist = 1, nwalked = 0, nreached = 0;
    ring[i] = level;
    for (int k = 0; k < n_own; ++k)
    {
      tag[own[k]] = 1;
      dist[own[k]] = 0.0;
    }
    list[0] = i;
    double mindist = 0.0;
    while (mindist + minseg <= dmax && nlist != 0)
    {
      ++level;
      mindist = INFINITY;
      int64_t found = 0;
      for (int64_t m = 0; m < nlist; ++m)
      {
        const int64_t *seg = segs + 4 * list[m];
        const int n = remove_corners(seg);
        for (int k = 0; k < n; ++k)
          tag[seg[k]] = 2;
        for (int k = 0; k < n; ++k)
        {
          const int64_t a = seg[k];
          if (expanded[a])
            continue;
          expanded[a] = 1;
          for (int64_t e = at[a]; e < at[a + 1]; ++e)
          {
            const int64_t j = at_segs[e];
            if (ring[j] != 0 && ring[j] != level)
              continue;
            if (ring[j] == 0)
              next[found++] = j;
            ring[j] = level;
            const int64_t *other = segs + 4 * j;
            const int n_other = remove_corners(other);
            for (int l = 0; l < n_other; ++l)
            {
              const int64_t b = other[l];
              if (!secondary[b] || tag[b] == 2)
                continue;
              const double d = dist[a] + mesh_distance(x, b, a);
              dist[b] = d < dist[b] ? d : dist[b];
              mindist = dist[b] < mindist ? dist[b] : mindist;
              if (tag[b] == 0)
              {
                reached[nreached++] = b;
                tag[b] = 1;
              }
              if (variable)
              {
                double g = fmin(node_gap[b] + seg_gap[i], node_size[b] + seg_size[i]);
                g = g < gap_max ? g : gap_max;
                gapv[b] = g > gap ? g : gap;
              }
            }
          }
        }
        for (int k = 0; k < n; ++k)
          tag[seg[k]] = 1;
      }
      for (int64_t m = 0; m < nlist; ++m)
      {
        const int64_t *seg = segs + 4 * list[m];
        for (int k = 0; k < remove_corners(seg); ++k)
          expanded[seg[k]] = 0;
      }
      nlist = found;
      for (int64_t m = 0; m < found; ++m)
      {
        list[m] = next[m];
        walked[nwalked++] = next[m];
      }
    }
    /* The nodes within reach along the mesh, sorted; then the state back to none. */
    const int64_t first = count;
    for (int64_t r = 0; r < nreached; ++r)
    {
      const int64_t b = reached[r];
      const double limit = variable ? root2 * gapv[b] : dmax;
      if (dist[b] <= limit)
      {
        if (count < capacity)
          removed[count] = b;
        ++count;
      }
      dist[b] = INFINITY;
    }
    if (count <= capacity)
      qsort(removed + first, count - first, sizeof(int64_t), remove_order);
    offsets[i + 1] = count;
    for (int64_t w = 0; w < nwalked; ++w)
    {
      const int64_t *seg = segs + 4 * walked[w];
      for (int k = 0; k < remove_corners(seg); ++k)
        tag[seg[k]] = 0;
      ring[walked[w]] = 0;
    }
    for (int k = 0; k < n_own; ++k)
    {
      tag[own[k]] = 0;
      dist[own[k]] = INFINITY;
    }
    ring[i] = 0;
  }
  free(at);
  free(at_segs);
  free(dist);
  free(gapv);
  free(tag);
  free(expanded);
  free(ring);
  free(list);
  free(next);
  free(walked);
  free(reached);
  return count;
}
