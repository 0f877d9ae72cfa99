/* particle_cost.c — the particle scheme's cost harness (its budget: ≤ 1 million instructions per step at
 * 1 000 particles on a floor plan of 5 000 segments). Builds a 200 m × 100 m floor of 5 m rooms (every
 * room wall split by a 1 m door) plus furniture segments up to 5 000 walls, indexes it, seeds the cloud
 * in a room and walks STEPS steps (a walker bouncing off the walls, PDR heading 5° off with noise) with
 * a Wi-Fi-like fix (σ 3 m) every 4th step, through the scheme's own calls (sf_fusion_step_on_floor,
 * sf_fusion_fix). callgrind counts the instructions inside those calls (--toggle-collect); the bench
 * divides by the number of calls. With "ekf" after STEPS the ekf scheme walks the same steps and fixes
 * instead (`stridefix-lab bench perf`'s per-update figures). Prints the plan's figures; exit 0, 2 on bad
 * usage. Usage: sf_particle_cost [STEPS [particle|ekf]] */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_fusion.h"
#include "sf_particle.h"
#include "sf_rng.h"
#include "sf_wall_grid.h"

enum { N_WALLS = 5000, W_M = 200, H_M = 100, ROOM_M = 5 };
static float x0s[N_WALLS], y0s[N_WALLS], x1s[N_WALLS], y1s[N_WALLS];
static int16_t fls[N_WALLS];
static int n;
static sf_particle_state_t states[SF_PARTICLE_MAX];
static int16_t floors[SF_PARTICLE_MAX];

static void add(const double ax, const double ay, const double bx, const double by)
{
    if (n < N_WALLS) {
        x0s[n] = (float)ax, y0s[n] = (float)ay, x1s[n] = (float)bx, y1s[n] = (float)by, fls[n] = 0;
        n++;
    }
}

static void building(sf_rng_t *const r)
{
    for (int j = 0; j <= H_M / ROOM_M; j++) { /* room walls along x, each with a door in the middle */
        for (int i = 0; i < W_M / ROOM_M; i++) {
            add(i * ROOM_M, j * ROOM_M, i * ROOM_M + 2.0, j * ROOM_M);
            add(i * ROOM_M + 3.0, j * ROOM_M, (i + 1) * ROOM_M, j * ROOM_M);
        }
    }
    for (int i = 0; i <= W_M / ROOM_M; i++) { /* and along y */
        for (int j = 0; j < H_M / ROOM_M; j++) {
            add(i * ROOM_M, j * ROOM_M, i * ROOM_M, j * ROOM_M + 2.0);
            add(i * ROOM_M, j * ROOM_M + 3.0, i * ROOM_M, (j + 1) * ROOM_M);
        }
    }
    while (n < N_WALLS) { /* furniture: 0.5-1.5 m segments inside the rooms, off the doors */
        const double x = floor(sf_rng_uniform(r) * W_M / ROOM_M) * ROOM_M, y = floor(sf_rng_uniform(r) * H_M / ROOM_M) * ROOM_M;
        const double a = 6.283185307179586 * sf_rng_uniform(r), len = 0.5 + sf_rng_uniform(r);
        const double cx = x + 1.0 + 1.5 * sf_rng_uniform(r), cy = y + 1.0 + 1.5 * sf_rng_uniform(r);
        add(cx, cy, cx + len * cos(a), cy + len * sin(a));
    }
}

static bool crosses(const sf_wall_grid_t *const g, const double ax, const double ay, const double bx, const double by)
{
    return sf_wall_grid_crosses(g, 0, ax, ay, bx, by);
}

int main(int argc, char **argv)
{
    const int steps = argc > 1 ? atoi(argv[1]) : 400;
    /* the scheme walked: the particle cloud (default) or the ekf on the same steps and fixes */
    const bool ekf = argc > 2 && strcmp(argv[2], "ekf") == 0;
    if (steps <= 0 || (argc > 2 && !ekf && strcmp(argv[2], "particle") != 0)) {
        fprintf(stderr, "usage: particle_cost [STEPS [particle|ekf]]\n");
        return 2;
    }
    sf_rng_t r;
    sf_rng_seed(&r, 42u, 1u);
    building(&r);
    const sf_floor_plan_t plan = {.n_walls = n, .x0_m = x0s, .y0_m = y0s, .x1_m = x1s, .y1_m = y1s, .floor = fls};
    sf_params_t p;
    sf_params_default(&p);
    const size_t bytes = sf_wall_grid_bytes(&plan, p.particle_grid_cell_m);
    int32_t *const mem = malloc(bytes); /* DEVIATION: a harness, not the core: the board's allocation */
    sf_wall_grid_t g;
    if (mem == NULL || sf_wall_grid_build(&g, &plan, p.particle_grid_cell_m, mem, bytes) != 0) {
        return 1;
    }
    sf_particle_t c;
    if (sf_particle_init(&c, &p, states, floors, SF_PARTICLE_MAX) != 0) {
        return 1;
    }
    sf_particle_set_map(&c, &g, NULL);
    sf_fusion_t f;
    sf_fusion_init(&f, ekf ? sf_scheme_ekf : sf_scheme_particle);
    if (!ekf) {
        sf_fusion_set_cloud(&f, &p, &c);
    }
    double x = 52.5, y = 52.5, h = 0.3;
    (void)sf_fusion_init_at(&f, &p, 0, x, y, 0, 0.5, 0);
    int fixes = 0;
    for (int i = 0; i < steps; i++) {
        const int64_t t = (int64_t)(i + 1) * 500000;
        h += 0.2 * (sf_rng_uniform(&r) - 0.5);
        double nx = x + 0.7 * cos(h), ny = y + 0.7 * sin(h);
        for (int k = 0; k < 50 && crosses(&g, x, y, nx, ny); k++) { /* the walker turns away from walls */
            h += 1.0 + sf_rng_uniform(&r);
            nx = x + 0.7 * cos(h), ny = y + 0.7 * sin(h);
        }
        if (!crosses(&g, x, y, nx, ny)) {
            x = nx, y = ny;
        }
        const double hp = h + 0.087 + 0.05 * (sf_rng_uniform(&r) - 0.5);
        sf_fusion_step_on_floor(&f, &p, t, 0.7 * cos(hp), 0.7 * sin(hp), 0.7, 0);
        if (i % 4 == 3) {
            const sf_fix_t fx = {.t_us = t + 1, .method = sf_fix_wifi, .x_m = x + 3.0 * sf_rng_normal(&r),
                                 .y_m = y + 3.0 * sf_rng_normal(&r), .accuracy_m = 3.0, .n_ap_used = 8};
            sf_fix_audit_t a;
            (void)sf_fusion_fix(&f, &p, &fx, 0, &a);
            fixes++;
        }
    }
    sf_pose_t pose = {0};
    (void)sf_fusion_pose(&f, &p, (int64_t)steps * 500000 + 1, 0, &pose);
    printf("{\"scheme\": \"%s\", \"walls\": %d, \"grid_bytes\": %zu, \"cell_m\": %.3f, \"particles\": %d, \"steps\": %d, \"fixes\": %d, "
           "\"deaths\": %u, \"resamples\": %u, \"all_blocked\": %u, \"recoveries\": %u, \"final_error_m\": %.3f}\n",
           ekf ? "ekf" : "particle", n, bytes, g.floors[0].cell_m, ekf ? 0 : c.n, steps, fixes, c.deaths, c.resamples, c.all_blocked, f.recoveries,
           hypot(pose.x_m - x, pose.y_m - y));
    free(mem);
    return 0;
}
