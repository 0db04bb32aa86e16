/* Batches of cells for the element kernels.
 *
 * A kernel works on LANES cells at a time: it gathers their nodal values into
 * `vec`s (GCC vector types of LANES doubles, one lane per cell), computes the
 * batch with the per-cell formulas written on `vec`s, which the compiler
 * emits as SIMD instructions of the host's width (one instruction per operation
 * where the vector is as wide as the host's registers, several on narrower
 * hosts), and scatters the nodal forces back.  A short last batch repeats its
 * first cell in the unused lanes, whose results are dropped.
 *
 * LANES is 8 (512 bits) on hosts with AVX-512, 4 (256 bits) elsewhere.  With
 * AVX-512, 8 lanes against 4 take the time per cell down on an AMD Zen 5
 * (full-width 512-bit units) by 25-45 % for the shells and 10-35 % for the
 * hexahedra, on a Zen 4 (512-bit operations in two halves) by 7-16 % and 1-8 %
 * (docs/performance.md); a cell's results do not depend on the lane count but for
 * round-off where a plastic return iterates until all the batch's lanes converge, its
 * energies' sums over a batch change in their last bits (tests/unit/test_kernel_lanes.py).
 *
 * Node arrays are (num_nodes, 3) row-major float64: node i's x, y, z are at
 * 3i, 3i + 1, 3i + 2.  Cells are (num_cells, nodes_per_cell) int32 rows of node
 * indices in DOLFINx's reference-cell order.
 */
#ifndef RWALL_BATCH_H
#define RWALL_BATCH_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#if defined(__AVX__)
#include <immintrin.h>
#endif

#if defined(__AVX512F__)
#define LANES 8
#else
#define LANES 4
#endif
#define INLINE static inline __attribute__((always_inline))

typedef double vec __attribute__((vector_size(LANES * sizeof(double))));
typedef int64_t ivec __attribute__((vector_size(LANES * sizeof(int64_t))));
#define VZERO ((vec){0.0})

#define TABLE_ROWS 64

/* Material and technology constants of one kernel call. */
typedef struct
{
  double lmbda;       /* first Lame parameter lambda, Pa */
  double mu;          /* shear modulus, Pa */
  double density;     /* kg/m^3 */
  double wave_speed;  /* dilatational wave speed sqrt((lambda + 2 mu)/density), m/s */
  double hourglass_coefficient; /* scales the hourglass forces (one-point hexahedra) */
  double dt;          /* the step just taken, dt^{n-1/2}, s (0 at the first step) */
  /* plasticity (plasticity.h) */
  int hardening;                /* HARDENING_LINEAR, _POWER, _TABLE or JOHNSON_COOK */
  double yield_stress;          /* A, Pa */
  double hardening_modulus;     /* H, Pa (linear) */
  double hardening_coefficient; /* B, Pa (power law, Johnson-Cook) */
  double hardening_exponent;    /* n */
  double rate_coefficient;      /* C (Johnson-Cook) */
  double reference_rate;        /* 1/s (Johnson-Cook) */
  int thermal;                  /* adiabatic heating and thermal softening (Johnson-Cook) */
  double thermal_exponent;      /* m */
  double melting_temperature;   /* K */
  double room_temperature;      /* K */
  double specific_heat;         /* J/(kg K) */
  double taylor_quinney;        /* share of plastic work turned into heat */
  int table_size;               /* rows of the table */
  double table_strain[TABLE_ROWS], table_stress[TABLE_ROWS]; /* eps_p (increasing), Pa */
  double max_flow_stress;       /* Pa, the cap on the law (0: none; plasticity.h) */
  /* the element time step (step.h) */
  int estimate;                 /* estimate each cell's stable step in this call */
  double calibration;           /* scales the estimates L / c to the exact limit at rest */
  const double *length0;        /* per cell: characteristic length at rest, m */
  const double *volume0;        /* per cell: volume at rest, m^3 */
  const double *step_factor;    /* NULL, or per cell sqrt(mass / mass at rest) (mass scaling) */
  double step_floor;            /* s: the cells whose step is below it are listed in below */
  int32_t *below;               /* NULL, or room for every cell's index */
  double *below_step;           /* and for its step before mass scaling, s */
  const double *nodal_mass;     /* NULL, or per cell the mass each of its nodes has of it, kg */
  double *nodal_stiffness;      /* and per node: adds m_c / dt_e^2 of each cell (N/m; step.h) */
  /* failure and erosion (failure.h) */
  int failure;                  /* FAILURE_NONE, FAILURE_PLASTIC_STRAIN or FAILURE_JOHNSON_COOK */
  double failure_strain;        /* eps_f of FAILURE_PLASTIC_STRAIN */
  double damage_constants[5];   /* D1 .. D5 of FAILURE_JOHNSON_COOK */
  double damage_reference_rate; /* 1/s, of its rate term */
  int damage_slot;              /* the state's row of the first point's damage D */
  int erode;                    /* decide erosion in this call (0: the cells only compute) */
  double erode_step;            /* s: a cell whose step estimate is below it is eroded (0: none) */
  const int32_t *live;          /* NULL: every cell; else the live cells' indices, increasing */
  int32_t *eroded;              /* room for every cell's index: the cells eroded in this call */
  double *cell_work;            /* NULL, or per cell its plastic work (row 0) and hourglass work
                                   (row 1) so far, J, rows of cell_stride values */
  int64_t cell_stride;
  const double *velocity;       /* v^{n-1/2} of the nodes, m/s (what an eroded cell did last) */
} element_params;

/* The cells of a batch: lane k holds cell id[k] (the lanes from nb on repeat the first);
 * `run` when they are LANES consecutive cells, whose per-cell values load as one vector. */
typedef struct
{
  int64_t id[LANES];
  int nb;
  int run;
} batch_t;

/* The batch of the cells k0 .. k0 + LANES - 1 of the n computed: the cells themselves, or
 * when `live` is given (the live cells' indices, increasing), live[k0 ..]. */
INLINE batch_t batch_at(const int32_t *restrict live, int64_t k0, int64_t n)
{
  batch_t b;
  b.nb = n - k0 < LANES ? (int)(n - k0) : LANES;
  for (int k = 0; k < LANES; ++k)
  {
    const int64_t j = k0 + (k < b.nb ? k : 0);
    b.id[k] = live ? live[j] : j;
  }
  b.run = b.nb == LANES && b.id[LANES - 1] - b.id[0] == LANES - 1;
  return b;
}

/* Gather the 3 components of the npe nodes of the batch's cells into out[3 I + i][lane]:
 * where the host has AVX-512 (VL; LANES 8) node by node, each lane's node as one masked load
 * of its x, y, z (the lane past z is not read), two 4 x 4 transposes of four lanes each and
 * their halves joined (element by element into the vectors, 8 lanes cost the kernels 20-35
 * ns more per cell: docs/performance.md). */
INLINE void gather(const int32_t *restrict cells, int npe, const batch_t *b,
                   const double *restrict values, vec *restrict out)
{
#if defined(__AVX512VL__) && LANES == 8
  for (int I = 0; I < npe; ++I)
  {
    __m256d half[2][3];
    for (int h = 0; h < 2; ++h)
    {
      __m256d r[4];
      for (int k = 0; k < 4; ++k)
        r[k] = _mm256_maskz_loadu_pd(0x7, values + 3 * (int64_t)cells[b->id[4 * h + k] * npe + I]);
      const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
      const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
      half[h][0] = _mm256_permute2f128_pd(t0, t2, 0x20);
      half[h][1] = _mm256_permute2f128_pd(t1, t3, 0x20);
      half[h][2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    }
    for (int i = 0; i < 3; ++i)
      out[3 * I + i] = (vec)_mm512_insertf64x4(_mm512_castpd256_pd512(half[0][i]), half[1][i], 1);
  }
#else
  for (int k = 0; k < LANES; ++k)
  {
    const int32_t *cell = cells + b->id[k] * npe;
    for (int I = 0; I < npe; ++I)
      for (int i = 0; i < 3; ++i)
        out[3 * I + i][k] = values[3 * (int64_t)cell[I] + i];
  }
#endif
}

/* Add the nodal forces in[3 I + i][lane] of the batch's nb valid lanes to f. */
INLINE void scatter_add(const int32_t *restrict cells, int npe, const batch_t *b,
                        const vec *restrict in, double *restrict f)
{
  for (int k = 0; k < b->nb; ++k)
  {
    const int32_t *cell = cells + b->id[k] * npe;
    for (int I = 0; I < npe; ++I)
      for (int i = 0; i < 3; ++i)
        f[3 * (int64_t)cell[I] + i] += in[3 * I + i][k];
  }
}

INLINE void cross(const vec a[3], const vec b[3], vec out[3])
{
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

INLINE vec dot3(const vec a[3], const vec b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Lane-wise |x| (the sign bit cleared), log and cbrt: the vector types have no such
 * operators.  Divisions are slow SIMD instructions: the kernels divide once and multiply. */
INLINE vec vabs(vec x)
{
  return (vec)((ivec)x & ((ivec){0} + INT64_MAX));
}

/* Natural log to about one ulp, all lanes at once: x = m 2^e with m in [sqrt(1/2), sqrt(2)),
 * log x = e log 2 + 2 atanh(s), s = (m - 1)/(m + 1), |s| < 0.172, by 14 terms of the series
 * 2 (s + s^3/3 + s^5/5 + ...) (the next term is below 1e-19 of the sum).  NaN for x <= 0
 * and for NaN, +inf for +inf, like log(). */
INLINE vec vlog(vec x)
{
  const ivec bits = (ivec)x;
  ivec e = ((bits >> 52) & 0x7ff) - 1023;
  vec m = (vec)((bits & 0x000fffffffffffffLL) | 0x3ff0000000000000LL); /* in [1, 2) */
  const ivec big = m > 1.41421356237309504880;
  m = (vec)(((ivec)(0.5 * m) & big) | ((ivec)m & ~big));
  e -= big; /* big is -1 where true */
  const vec s = (m - 1.0) / (m + 1.0), s2 = s * s;
  vec series = VZERO + 1.0 / 27.0;
  for (int k = 12; k >= 0; --k)
    series = series * s2 + 1.0 / (2 * k + 1);
  const vec r = 2.0 * s * series + 0.69314718055994530942 * __builtin_convertvector(e, vec);
  const ivec finite = (x > 0.0) & (x < INFINITY), infinite = x == INFINITY;
  const ivec special = ((ivec)(VZERO + INFINITY) & infinite) | ((ivec)(VZERO + NAN) & ~infinite);
  return (vec)(((ivec)r & finite) | (special & ~finite));
}

INLINE vec vmax(vec a, vec b)
{
  const ivec m = a > b;
  return (vec)(((ivec)a & m) | ((ivec)b & ~m));
}

INLINE vec vmin(vec a, vec b)
{
  const ivec m = a < b;
  return (vec)(((ivec)a & m) | ((ivec)b & ~m));
}

/* e^x to about one ulp, all lanes at once, for x in [-708, 709] (clipped there): x = n log 2
 * + r with n the nearest integer of x / log 2, |r| <= log(2) / 2, e^r by 14 terms of its
 * series (the next is below 1e-17 of the sum), times 2^n set in the exponent bits. */
INLINE vec vexp(vec x)
{
  x = vmin(vmax(x, VZERO - 708.0), VZERO + 709.0);
  const double shift = 6755399441055744.0; /* 1.5 2^52: adding it rounds to an integer */
  const vec n = (x * 1.44269504088896340736 + shift) - shift;
  const vec r = (x - n * 6.93147180369123816490e-01) - n * 1.90821492927058770002e-10;
  vec series = VZERO + 1.0 / 87178291200.0; /* 1/14! */
  double factorial = 87178291200.0;
  for (int k = 13; k >= 0; --k)
  {
    factorial /= (k + 1);
    series = series * r + 1.0 / factorial;
  }
  const ivec bits = (__builtin_convertvector(n, ivec) + 1023) << 52;
  return series * (vec)bits;
}

INLINE vec vcbrt(vec x)
{
  vec r;
  for (int k = 0; k < LANES; ++k)
    r[k] = cbrt(x[k]);
  return r;
}

INLINE vec vsqrt(vec x)
{
  vec r;
  for (int k = 0; k < LANES; ++k)
    r[k] = sqrt(x[k]);
  return r;
}

INLINE vec vselect(ivec m, vec a, vec b)
{
  return (vec)(((ivec)a & m) | ((ivec)b & ~m));
}

/* Whether some lane of m is non-zero: one test instruction where the host has AVX-512 (8
 * lanes) or AVX (4 lanes), a loop over the lanes elsewhere. */
INLINE int any_lane(ivec m)
{
#if defined(__AVX512F__) && LANES == 8
  return _mm512_test_epi64_mask((__m512i)m, (__m512i)m) != 0;
#elif defined(__AVX__) && LANES == 4
  return !_mm256_testz_si256((__m256i)m, (__m256i)m);
#else
  int r = 0;
  for (int k = 0; k < LANES; ++k)
    r |= m[k] != 0;
  return r;
#endif
}

/* The per-cell values a[id] of the batch's cells. */
INLINE vec cell_values(const double *restrict a, const batch_t *b)
{
  vec v;
  if (b->run)
    __builtin_memcpy(&v, a + b->id[0], sizeof v);
  else
    for (int k = 0; k < LANES; ++k)
      v[k] = a[b->id[k]];
  return v;
}

/* Store the per-cell values v of the batch's nb valid lanes in a[id]. */
INLINE void set_cell_values(double *restrict a, const batch_t *b, vec v)
{
  if (b->run)
    __builtin_memcpy(a + b->id[0], &v, sizeof v);
  else
    for (int k = 0; k < b->nb; ++k)
      a[b->id[k]] = v[k];
}

/* The sum of the first nb lanes. */
INLINE double lane_sum(vec x, int nb)
{
  double s = 0.0;
  for (int k = 0; k < nb; ++k)
    s += x[k];
  return s;
}

#endif
