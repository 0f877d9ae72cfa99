/* sf_particle.h — the `particle` scheme's math: a map-aware particle filter over PDR steps. The control
 * around it (start, floor, gate, recovery, audit) is sf_fusion's (sf_fusion_particle.c); this module
 * is the cloud.
 *
 * State per particle: position (x, y) [m, map frame], floor (int16), heading bias b [rad] added to the
 * PDR walking direction, stride scale s multiplying the PDR step length, weight w. Weights are linear
 * and normalised (Σ w = 1) after every step and fix: the effective sample size 1/Σw² and systematic
 * resampling need linear weights, and the fix likelihood's uniform share (below) bounds how far one
 * update can spread them (a factor 1/outlier_share at most), so after the normalisation nothing
 * underflows; log weights would cost an exp per particle wherever they are used.
 *
 * Propagation per PDR step (length L, walking direction ψ, both the estimator's), per particle, with
 * four N(0, 1) deviates n1..n4 of the cloud's own PCG32 (sf_rng.h; particle.seed, so a replay is
 * bit-identical and another seed gives another cloud):
 *     s ← clamp(s + √(q_s·L)·n3, scale_min, scale_max),  b ← b + √(q_b·L)·n4   (random walks per metre)
 *     d = s·L·(1 + σ_L·n1),  θ = ψ + b + σ_ψ·n2,  (x, y) ← (x, y) + d·(cos θ, sin θ).
 * A particle whose step crosses a wall of its floor (sf_wall_grid.h) dies (w = 0; it lies where the step
 * took it, weightless, until the next resampling replaces it). If every particle
 * would die, none does: the step is taken as if there were no walls (counted in all_blocked): a map
 * error or a wrong floor must never lose the track; the fixes and the next walls sort it out.
 * Floors: when the barometric floor (passed with every step and fix) differs from a particle's, the
 * particle moves to it only inside a port that joins the two floors (stairs or elevator, disc of the
 * port's radius around its centre, at the step's start or end); with no such ports on the site, anywhere.
 * A particle on another floor than the barometer's loses weight, × floor_mismatch_weight per step.
 * If the ports miss a real staircase, the cloud stays on the old floor (the pose's floor lags the
 * barometer's) until a fix re-seeds it.
 *
 * Measurement per fix (Wi-Fi, BLE, GNSS, landmark alike, each with its own 1σ accuracy σ):
 *     g_i = exp(−|z − x_i|² / (2σ²)),  w_i ← w_i · ((1 − ε)·g_i + ε),  ε = outlier_share,
 * a Gaussian of the fix's accuracy mixed with a uniform outlier share, so one wild fix cannot kill the
 * cloud. The evidence E = Σ w_i g_i ∈ [0, 1] (how much of the cloud lies near the fix) is what the
 * control judges (sf_fusion_particle.c); the effective weight change (total variation ½Σ|w'_i − w_i|,
 * 0 = nothing moved, 1 = a new distribution) is the audit's α.
 * Resampling: systematic (one uniform), in place, when ESS < resample_ess_ratio · N; after a step (walls
 * killed some) and after a fix.
 *
 * Memory: the caller's array of N particles, sizeof(sf_particle_state_t) = 32 B each (checked):
 * 1 000 particles 32 kB, SF_PARTICLE_MAX (2 048) 64 kB; sizeof(sf_particle_t) ≤ 128 B (checked).
 * Cost per step: per particle 4 normals (2 polar pairs: 2 log, 2 sqrt), one sin and cos, the wall
 * query (sf_wall_grid.h: the cells on the step's path); per fix one exp per particle; resampling O(N).
 * Measured (make bench, particle-cost): see out/bench/particle_cost.json. No heap, no I/O, no clock.
 * Errors: sf_particle_init returns SF_OK or SF_EINVAL (NULL memory, capacity outside 1..SF_PARTICLE_MAX);
 * everything else cannot fail. */
#ifndef SF_PARTICLE_H
#define SF_PARTICLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_rng.h"
#include "sf_wall_grid.h"

typedef struct {
    double x_m;
    double y_m;
    double w;       /* normalised linear weight */
    float bias_rad; /* heading bias b */
    float scale;    /* stride scale s */
} sf_particle_state_t;
_Static_assert(sizeof(sf_particle_state_t) == 32, "sf_particle.h promises 32 B per particle");

typedef struct {
    sf_particle_state_t *p; /* [capacity], caller-owned */
    int16_t *floor;         /* [capacity], caller-owned, each particle's floor */
    int32_t capacity;
    int32_t n;                   /* particles in use: min(particle.count, capacity) */
    sf_rng_t rng;
    const sf_wall_grid_t *walls; /* NULL: no walls */
    const sf_ports_t *ports;     /* NULL or no stairs/elevator: floors change anywhere */
    bool seeded;
    /* counters, never decrease */
    uint32_t steps, deaths, all_blocked, resamples, seeds, floor_changes;
    uint32_t detours, jumps; /* the published track (sf_particle_reachable): mean replaced, no way found */
    uint32_t injections;     /* sf_particle_inject calls (recoveries) */
} sf_particle_t;
_Static_assert(sizeof(sf_particle_t) <= 128, "sf_particle.h promises at most 128 B");

/* Bytes of caller memory for n particles (state and floor arrays). */
#define SF_PARTICLE_BYTES_PER (sizeof(sf_particle_state_t) + sizeof(int16_t))

/* The cloud's summary: weighted mean and covariance, ESS, the weight's majority floor. */
typedef struct {
    double x_m, y_m;
    double cov_m2[3]; /* [xx, xy, yy] */
    double ess;
    int16_t floor;
    double bias_rad, scale; /* weighted means */
} sf_particle_summary_t;

/* An unseeded cloud over the caller's arrays; the generator seeded with particle.seed. */
int sf_particle_init(sf_particle_t *c, const sf_params_t *p, sf_particle_state_t *states, int16_t *floors,
                     int32_t capacity);

/* The site's walls and ports (either NULL: none). Caller-owned, must outlive the cloud. */
void sf_particle_set_map(sf_particle_t *c, const sf_wall_grid_t *walls, const sf_ports_t *ports);

/* Every particle drawn around (x, y) with per-axis σ, on floor, equal weights; bias and scale drawn
 * from their priors for a new cloud (keep_gait false) or kept per particle (a re-seed). */
void sf_particle_seed(sf_particle_t *c, const sf_params_t *p, double x_m, double y_m, double sigma_m, int16_t floor,
                      bool keep_gait);

/* Recovery without forgetting (augmented MCL, Thrun et al., "Probabilistic Robotics" §8.3.5): every
 * round(1/share)-th particle is redrawn around (x, y) with per-axis σ on floor, at weight 1/N, keeping
 * its gait; then the weights are normalised, so the new hypothesis holds about `share` of the weight
 * and the old one the rest. The next fixes decide between them: one wrong fix after a run of
 * rejections cannot move the whole cloud (and its track) into a room the walker is not in. */
void sf_particle_inject(sf_particle_t *c, double x_m, double y_m, double sigma_m, int16_t floor, double share);

/* One PDR step (see the header); baro_floor INT16_MIN: no floor logic. */
void sf_particle_step(sf_particle_t *c, const sf_params_t *p, double length_m, double heading_rad,
                      int16_t baro_floor);

/* Floor transitions at the particles' positions (a fix, a pose: the walker may stand in a lift). */
void sf_particle_floors(sf_particle_t *c, int16_t baro_floor);

/* E = Σ w_i exp(−|z − x_i|² / (2σ²)). */
double sf_particle_evidence(const sf_particle_t *c, double x_m, double y_m, double sigma_m);

/* The fix's likelihood applied (see the header), resampled if needed; returns the effective weight
 * change α ∈ [0, 1]; *ess_after is the ESS right after the update, before any resampling. */
double sf_particle_update(sf_particle_t *c, const sf_params_t *p, double x_m, double y_m, double sigma_m,
                          double *ess_after);

/* Systematic resampling now (equal weights after); the count stays. */
void sf_particle_resample(sf_particle_t *c);

void sf_particle_summary(const sf_particle_t *c, sf_particle_summary_t *s);

/* Particles of a strided sample probed for sf_particle_reachable (bounds its cost: as many wall
 * queries of the grid, only when the cloud's mean is behind a wall). */
#define SF_PARTICLE_PROBES 64
/* Below this share of the probed weight within reach, the cloud is elsewhere and the track jumps to it. */
#define SF_PARTICLE_REACH_SHARE 0.2

/* The published track walks like the walker: the cloud's weighted mean can lie behind a wall from the
 * previous published position (a cloud in two rooms, a door's corner cut by the mean), and a track
 * through walls is no walker's. This is the weighted mean of the particles on `floor` reachable in a
 * straight line from (x0, y0) without crossing a wall (a strided sample of SF_PARTICLE_PROBES of them),
 * or — when that mean is itself behind a wall (the reachable particles round a corner) — the
 * reachable particle nearest (mx, my), the cloud's mean. Fills (*x, *y) and returns true; false when the
 * reachable particles hold less than SF_PARTICLE_REACH_SHARE of the probed weight (the cloud is elsewhere
 * — a track stuck on the wrong side of a wall must not hold it there: the caller takes the mean, a jump).
 * Cost: ≤ SF_PARTICLE_PROBES + 1 wall queries. */
bool sf_particle_reachable(const sf_particle_t *c, int16_t floor, double x0_m, double y0_m, double mx_m,
                           double my_m, double *x_m, double *y_m);

double sf_particle_ess(const sf_particle_t *c);

#endif
