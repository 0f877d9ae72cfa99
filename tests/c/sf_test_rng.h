/* sf_test_rng.h — seeded noise for the C tests (xorshift64* + Box-Muller): the same sequence on every
 * platform, so test outputs and printed measurements are reproducible (header-only). */
#ifndef SF_TEST_RNG_H
#define SF_TEST_RNG_H

#include <math.h>
#include <stdint.h>

typedef struct {
    uint64_t s; /* the state: set it to the seed (non-zero) */
} rng_t;

static inline double rng_uniform01(rng_t *const r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return (double)((r->s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* uniform in [−1, 1) */
static inline double rng_pm1(rng_t *const r)
{
    return 2.0 * rng_uniform01(r) - 1.0;
}

static inline double rng_gauss(rng_t *const r)
{
    const double u1 = rng_uniform01(r) + 1e-300;
    const double u2 = rng_uniform01(r);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2);
}

#endif
