/* sf_rng.c — PCG32 XSH-RR and the polar normal (see sf_rng.h). */
#include "sf_rng.h"

#include <math.h>

static const uint64_t pcg_mult = 6364136223846793005ULL;

uint32_t sf_rng_u32(sf_rng_t *const r)
{
    const uint64_t old = r->state;
    r->state = old * pcg_mult + r->inc;
    const uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

void sf_rng_seed(sf_rng_t *const r, const uint64_t seed, const uint64_t stream)
{
    r->state = 0u;
    r->inc = (stream << 1u) | 1u;
    r->has_spare = false;
    r->spare = 0.0;
    (void)sf_rng_u32(r);
    r->state += seed;
    (void)sf_rng_u32(r);
}

double sf_rng_uniform(sf_rng_t *const r)
{
    return ((double)sf_rng_u32(r) + 0.5) * (1.0 / 4294967296.0);
}

double sf_rng_normal(sf_rng_t *const r)
{
    if (r->has_spare) {
        r->has_spare = false;
        return r->spare;
    }
    double u, v, s;
    do {
        u = 2.0 * sf_rng_uniform(r) - 1.0;
        v = 2.0 * sf_rng_uniform(r) - 1.0;
        s = u * u + v * v;
    } while (s >= 1.0); /* s > 0 always: the uniforms are never exactly 1/2 */
    const double m = sqrt(-2.0 * log(s) / s);
    r->spare = v * m;
    r->has_spare = true;
    return u * m;
}
