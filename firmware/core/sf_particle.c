/* sf_particle.c — the cloud (see sf_particle.h): seed, step, floors, fix likelihood, resampling,
 * summary. */
#include "sf_particle.h"

#include <math.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_math.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define FLOOR_KEEP INT16_MIN

int sf_particle_init(sf_particle_t *const c, const sf_params_t *const p, sf_particle_state_t *const states,
                     int16_t *const floors, const int32_t capacity)
{
    if (c == NULL || states == NULL || floors == NULL || capacity < 1 || capacity > SF_PARTICLE_MAX) {
        return SF_EINVAL;
    }
    *c = (sf_particle_t){.p = states, .floor = floors, .capacity = capacity};
    c->n = p->particle_count < capacity ? p->particle_count : capacity;
    sf_rng_seed(&c->rng, (uint64_t)(uint32_t)p->particle_seed, 0x5f70617274u /* "_part" */);
    return SF_OK;
}

void sf_particle_set_map(sf_particle_t *const c, const sf_wall_grid_t *const walls, const sf_ports_t *const ports)
{
    c->walls = walls;
    c->ports = ports;
}

void sf_particle_seed(sf_particle_t *const c, const sf_params_t *const p, const double x_m, const double y_m,
                      const double sigma_m, const int16_t floor, const bool keep_gait)
{
    SF_ASSERT(c != NULL && p != NULL && c->n >= 1 && c->n <= c->capacity); /* sf_particle_init's */
    const double w = 1.0 / (double)c->n;
    const bool keep = keep_gait && c->seeded;
    for (int32_t i = 0; i < c->n; i++) {
        sf_particle_state_t *const q = &c->p[i];
        q->x_m = x_m + sigma_m * sf_rng_normal(&c->rng);
        q->y_m = y_m + sigma_m * sf_rng_normal(&c->rng);
        q->w = w;
        c->floor[i] = floor;
        if (!keep) {
            q->bias_rad = (float)(p->particle_init_bias_sigma_rad * sf_rng_normal(&c->rng));
            q->scale = (float)sf_clamp(1.0 + p->particle_init_scale_sigma * sf_rng_normal(&c->rng), p->particle_scale_min,
                                    p->particle_scale_max);
        }
    }
    c->seeded = true;
    c->seeds++;
}

/* Whether a port that joins floors a and b (stairs or elevator) holds (x, y). */
static bool in_port(const sf_ports_t *const ports, const int16_t a, const int16_t b, const double x_m,
                    const double y_m)
{
    const int16_t lo = a < b ? a : b, hi = a < b ? b : a;
    for (int32_t k = 0; k < ports->n_ports; k++) {
        if ((ports->kind[k] == sf_port_stairs || ports->kind[k] == sf_port_elevator) && ports->floor_lo[k] <= lo &&
            hi <= ports->floor_hi[k]) {
            const double dx = x_m - ports->x_m[k], dy = y_m - ports->y_m[k], r = ports->radius_m[k];
            if (dx * dx + dy * dy <= r * r) {
                return true;
            }
        }
    }
    return false;
}

static bool has_floor_ports(const sf_ports_t *const ports)
{
    for (int32_t k = 0; ports != NULL && k < ports->n_ports; k++) {
        if (ports->kind[k] == sf_port_stairs || ports->kind[k] == sf_port_elevator) {
            return true;
        }
    }
    return false;
}

/* Particle i moves to baro_floor if it may at (x0, y0) or (x1, y1). */
static void floor_transition(sf_particle_t *const c, const int32_t i, const int16_t baro_floor, const bool anywhere,
                             const double x0_m, const double y0_m)
{
    SF_ASSERT(i >= 0 && i < c->n);
    if (c->floor[i] == baro_floor || baro_floor == FLOOR_KEEP) {
        return;
    }
    const sf_particle_state_t *const q = &c->p[i];
    if (anywhere || in_port(c->ports, c->floor[i], baro_floor, x0_m, y0_m) ||
        in_port(c->ports, c->floor[i], baro_floor, q->x_m, q->y_m)) {
        c->floor[i] = baro_floor;
        c->floor_changes++;
    }
}

void sf_particle_floors(sf_particle_t *const c, const int16_t baro_floor)
{
    const bool anywhere = !has_floor_ports(c->ports);
    for (int32_t i = 0; i < c->n && c->seeded; i++) {
        floor_transition(c, i, baro_floor, anywhere, c->p[i].x_m, c->p[i].y_m);
    }
}

double sf_particle_ess(const sf_particle_t *const c)
{
    double s2 = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        s2 += c->p[i].w * c->p[i].w;
    }
    return s2 > 0.0 ? 1.0 / s2 : 0.0;
}

/* Divides by the sum; false (nothing changed) when the sum is not positive. */
static bool normalise(sf_particle_t *const c)
{
    double sum = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        sum += c->p[i].w;
    }
    if (!(sum > 0.0)) {
        return false;
    }
    const double inv = 1.0 / sum;
    for (int32_t i = 0; i < c->n; i++) {
        c->p[i].w *= inv;
    }
    return true;
}

void sf_particle_resample(sf_particle_t *const c)
{
    const int32_t n = c->n;
    SF_ASSERT(n >= 1 && n <= c->capacity);
    /* counts per particle (systematic: u_k = (u + k) / n), kept in the weights' place */
    int32_t last_alive = 0;
    for (int32_t i = 0; i < n; i++) {
        last_alive = c->p[i].w > 0.0 ? i : last_alive;
    }
    const double u = sf_rng_uniform(&c->rng);
    double cum = 0.0;
    int32_t k = 0;
    for (int32_t i = 0; i < n; i++) {
        cum += c->p[i].w;
        int32_t m = 0;
        while (k < n && ((double)k + u) / (double)n < cum) {
            m++;
            k++;
        }
        c->p[i].w = (double)m;
    }
    c->p[last_alive].w += (double)(n - k); /* what rounding left over */
    /* in place: every particle drawn m > 1 times fills m − 1 slots of particles drawn 0 times */
    int32_t free_slot = 0;
    for (int32_t i = 0; i < n; i++) {
        for (int32_t m = (int32_t)c->p[i].w; m > 1; m--) {
            while (c->p[free_slot].w != 0.0) {
                free_slot++;
                SF_ASSERT(free_slot < n); /* as many slots drawn 0 times as extra draws */
            }
            c->p[free_slot] = c->p[i];
            c->p[free_slot].w = 1.0; /* now taken */
            c->floor[free_slot] = c->floor[i];
        }
    }
    const double w = 1.0 / (double)n;
    for (int32_t i = 0; i < n; i++) {
        c->p[i].w = w;
    }
    c->resamples++;
}

static void resample_if_needed(sf_particle_t *const c, const sf_params_t *const p)
{
    if (sf_particle_ess(c) < p->particle_resample_ess_ratio * (double)c->n) {
        sf_particle_resample(c);
    }
}

void sf_particle_step(sf_particle_t *const c, const sf_params_t *const p, const double length_m,
                      const double heading_rad, const int16_t baro_floor)
{
    SF_ASSERT(c != NULL && p != NULL);
    SF_ASSERT(isfinite(length_m) && length_m >= 0.0); /* sf_fusion counts and skips any other step */
    if (!c->seeded) {
        return;
    }
    const double sd_scale = sqrt(p->particle_scale_rw_per_m * length_m);
    const double sd_bias = sqrt(p->particle_bias_rw_rad2_per_m * length_m);
    const bool walls = c->walls != NULL && c->walls->n_floors > 0;
    const bool anywhere = !has_floor_ports(c->ports);
    const double mismatch = p->particle_floor_mismatch_weight;
    double alive = 0.0;
    uint32_t died = 0;
    for (int32_t i = 0; i < c->n; i++) {
        sf_particle_state_t *const q = &c->p[i];
        const double n1 = sf_rng_normal(&c->rng), n2 = sf_rng_normal(&c->rng);
        const double n3 = sf_rng_normal(&c->rng), n4 = sf_rng_normal(&c->rng);
        const double s = sf_clamp((double)q->scale + sd_scale * n3, p->particle_scale_min, p->particle_scale_max);
        const double b = (double)q->bias_rad + sd_bias * n4;
        q->scale = (float)s;
        q->bias_rad = (float)(b > M_PI ? b - 2.0 * M_PI : (b < -M_PI ? b + 2.0 * M_PI : b)); /* one step < π */
        const double d = s * length_m * (1.0 + p->particle_length_sigma * n1);
        const double th = heading_rad + b + p->particle_heading_sigma_rad * n2;
        const double x0 = q->x_m, y0 = q->y_m;
        q->x_m = x0 + d * cos(th);
        q->y_m = y0 + d * sin(th);
        if (walls && q->w > 0.0 && sf_wall_grid_crosses(c->walls, c->floor[i], x0, y0, q->x_m, q->y_m)) {
            q->w = -q->w; /* dead unless every particle is (then the sign comes back) */
            died++;
        }
        floor_transition(c, i, baro_floor, anywhere, x0, y0);
        if (baro_floor != FLOOR_KEEP && c->floor[i] != baro_floor) {
            q->w *= mismatch;
        }
        alive += q->w > 0.0 ? q->w : 0.0;
    }
    const bool keep_all = !(alive > 0.0);
    for (int32_t i = 0; died > 0 && i < c->n; i++) {
        if (c->p[i].w < 0.0) {
            c->p[i].w = keep_all ? -c->p[i].w : 0.0;
        }
    }
    if (keep_all && died > 0) {
        c->all_blocked++;
    } else {
        c->deaths += died;
    }
    if (!normalise(c)) { /* every weight 0 (a mismatch weight of 0 everywhere): start equal */
        for (int32_t i = 0; i < c->n; i++) {
            c->p[i].w = 1.0 / (double)c->n;
        }
    }
    resample_if_needed(c, p);
    c->steps++;
}

double sf_particle_evidence(const sf_particle_t *const c, const double x_m, const double y_m, const double sigma_m)
{
    SF_ASSERT(c != NULL && sigma_m > 0.0); /* the fix's σ is floored at fusion.var_min_m2 > 0 */
    const double k = -0.5 / (sigma_m * sigma_m);
    double e = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        const double dx = c->p[i].x_m - x_m, dy = c->p[i].y_m - y_m;
        e += c->p[i].w * exp(k * (dx * dx + dy * dy));
    }
    return e;
}

double sf_particle_update(sf_particle_t *const c, const sf_params_t *const p, const double x_m, const double y_m,
                          const double sigma_m, double *const ess_after)
{
    SF_ASSERT(c != NULL && p != NULL && ess_after != NULL && sigma_m > 0.0);
    SF_ASSERT(p->particle_outlier_share > 0.0); /* its range: the sum below stays > 0 */
    const double k = -0.5 / (sigma_m * sigma_m), eps = p->particle_outlier_share;
    double sum = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        const double dx = c->p[i].x_m - x_m, dy = c->p[i].y_m - y_m;
        sum += c->p[i].w * ((1.0 - eps) * exp(k * (dx * dx + dy * dy)) + eps);
    }
    /* α = ½ Σ |w_i l_i / sum − w_i|, then the new weights; sum ≥ eps·Σw > 0 */
    double tv = 0.0, s2 = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        const double dx = c->p[i].x_m - x_m, dy = c->p[i].y_m - y_m;
        const double w = c->p[i].w * ((1.0 - eps) * exp(k * (dx * dx + dy * dy)) + eps) / sum;
        tv += fabs(w - c->p[i].w);
        s2 += w * w;
        c->p[i].w = w;
    }
    *ess_after = s2 > 0.0 ? 1.0 / s2 : 0.0;
    resample_if_needed(c, p);
    return sf_clamp(0.5 * tv, 0.0, 1.0);
}

void sf_particle_summary(const sf_particle_t *const c, sf_particle_summary_t *const s)
{
    *s = (sf_particle_summary_t){.floor = c->n > 0 ? c->floor[0] : 0, .scale = 1.0};
    double sw = 0.0, mx = 0.0, my = 0.0, mb = 0.0, ms = 0.0, s2 = 0.0;
    for (int32_t i = 0; i < c->n; i++) {
        const double w = c->p[i].w;
        sw += w;
        mx += w * c->p[i].x_m;
        my += w * c->p[i].y_m;
        mb += w * (double)c->p[i].bias_rad;
        ms += w * (double)c->p[i].scale;
        s2 += w * w;
    }
    if (!(sw > 0.0)) {
        return;
    }
    s->x_m = mx / sw;
    s->y_m = my / sw;
    s->bias_rad = mb / sw;
    s->scale = ms / sw;
    s->ess = sw * sw / s2;
    double xx = 0.0, xy = 0.0, yy = 0.0;
    /* the majority floor: up to 8 distinct floors tallied (more are a cloud in pieces: the first 8) */
    int16_t fl[8] = {s->floor};
    double fw[8] = {0.0};
    int nf = 0;
    for (int32_t i = 0; i < c->n; i++) {
        const double w = c->p[i].w, dx = c->p[i].x_m - s->x_m, dy = c->p[i].y_m - s->y_m;
        xx += w * dx * dx;
        xy += w * dx * dy;
        yy += w * dy * dy;
        int j = 0;
        while (j < nf && fl[j] != c->floor[i]) {
            j++;
        }
        if (j == nf && nf < 8) {
            fl[nf] = c->floor[i];
            fw[nf++] = 0.0;
        }
        if (j < nf) {
            fw[j] += w;
        }
    }
    s->cov_m2[0] = xx / sw;
    s->cov_m2[1] = xy / sw;
    s->cov_m2[2] = yy / sw;
    int best = 0;
    for (int j = 1; j < nf; j++) {
        best = fw[j] > fw[best] ? j : best;
    }
    s->floor = fl[best];
}

bool sf_particle_reachable(const sf_particle_t *const c, const int16_t floor, const double x0_m, const double y0_m,
                           const double mx_m, const double my_m, double *const x_m, double *const y_m)
{
    const int32_t stride = c->n > SF_PARTICLE_PROBES ? c->n / SF_PARTICLE_PROBES : 1;
    double sw = 0.0, sx = 0.0, sy = 0.0, best_d2 = INFINITY, bx = 0.0, by = 0.0, probed = 0.0;
    for (int32_t i = 0; i < c->n; i += stride) {
        const sf_particle_state_t *const q = &c->p[i];
        probed += q->w;
        if (c->floor[i] != floor || !(q->w > 0.0) ||
            (c->walls != NULL && sf_wall_grid_crosses(c->walls, floor, x0_m, y0_m, q->x_m, q->y_m))) {
            continue;
        }
        sw += q->w;
        sx += q->w * q->x_m;
        sy += q->w * q->y_m;
        const double d2 = (q->x_m - mx_m) * (q->x_m - mx_m) + (q->y_m - my_m) * (q->y_m - my_m);
        if (d2 < best_d2) {
            best_d2 = d2;
            bx = q->x_m;
            by = q->y_m;
        }
    }
    if (!(sw > 0.0) || sw < SF_PARTICLE_REACH_SHARE * probed) {
        return false; /* most of the cloud is elsewhere: the track follows it */
    }
    *x_m = sx / sw;
    *y_m = sy / sw;
    if (c->walls != NULL && sf_wall_grid_crosses(c->walls, floor, x0_m, y0_m, *x_m, *y_m)) {
        *x_m = bx;
        *y_m = by;
    }
    return true;
}

void sf_particle_inject(sf_particle_t *const c, const double x_m, const double y_m, const double sigma_m,
                        const int16_t floor, const double share)
{
    const int32_t k = share > 0.0 && share < 1.0 ? (int32_t)lround(1.0 / share) : 1;
    SF_ASSERT(c->n >= 1 && k >= 1);
    const double w = 1.0 / (double)c->n;
    for (int32_t i = 0; i < c->n; i += k) { /* every k-th: a strided, not a weight-ordered, choice */
        sf_particle_state_t *const q = &c->p[i];
        q->x_m = x_m + sigma_m * sf_rng_normal(&c->rng);
        q->y_m = y_m + sigma_m * sf_rng_normal(&c->rng);
        q->w = w; /* the particle keeps its gait (bias, scale): the walker's, not the position's */
        c->floor[i] = floor;
    }
    (void)normalise(c);
    c->injections++;
}
