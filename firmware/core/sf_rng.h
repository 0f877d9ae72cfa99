/* sf_rng.h — the core's seeded random numbers: PCG32 (O'Neill 2014, "PCG: a family of simple fast
 * space-efficient statistically good algorithms", XSH-RR output of a 64-bit LCG) and normal deviates by
 * Marsaglia's polar method (Marsaglia & Bray 1964: two independent N(0, 1) per accepted pair, no
 * trigonometry, no table; 21.5 % of pairs are redrawn).
 *
 * Why PCG32: 8 bytes of state, one 64-bit multiply per draw, passes TestU01's BigCrush, and its output
 * is defined bit for bit, so a replay with the same seed is bit-identical on every platform (the
 * particle filter's contract, sf_particle.h). The state is the caller's (no hidden globals).
 *
 * Cost: sf_rng_u32 ~6 integer ops; sf_rng_uniform ~8; sf_rng_normal2 ~40 flops + one log and one sqrt
 * per accepted pair (≈ 1.27 pairs drawn). Memory: 24 B (checked). Cannot fail. */
#ifndef SF_RNG_H
#define SF_RNG_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    uint64_t state;
    uint64_t inc;       /* stream selector, odd */
    double spare;       /* the second normal of the last polar pair */
    bool has_spare;
} sf_rng_t;
_Static_assert(sizeof(sf_rng_t) <= 32, "sf_rng.h promises at most 32 B");

/* Seeds the generator (any seed; stream picks one of 2^63 independent sequences). */
void sf_rng_seed(sf_rng_t *r, uint64_t seed, uint64_t stream);

/* The next 32 uniformly distributed bits. */
uint32_t sf_rng_u32(sf_rng_t *r);

/* Uniform in the open interval (0, 1): (k + 0.5) / 2^32, never 0 nor 1. */
double sf_rng_uniform(sf_rng_t *r);

/* One N(0, 1) deviate (the polar method's pairs, the second kept for the next call). */
double sf_rng_normal(sf_rng_t *r);

#endif
