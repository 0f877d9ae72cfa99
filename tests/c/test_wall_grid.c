/* test_wall_grid.c — the wall index (sf_wall_grid.h): the grid answers exactly what the brute force
 * over every wall answers, on random walls and steps, at several cell sizes; the touching and collinear
 * cases decided as the header says; memory as stated. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sf_error.h"
#include "sf_test_rng.h"
#include "sf_wall_grid.h"

enum { N_WALLS = 600 };
static float x0s[N_WALLS], y0s[N_WALLS], x1s[N_WALLS], y1s[N_WALLS];
static int16_t floors[N_WALLS];
static int32_t memory[1 << 18];

static bool brute(const sf_floor_plan_t *plan, const int16_t floor, const double ax, const double ay, const double bx,
                  const double by)
{
    for (int32_t i = 0; i < plan->n_walls; i++) {
        if (plan->floor[i] == floor && sf_wall_segments_cross(ax, ay, bx, by, plan->x0_m[i], plan->y0_m[i],
                                                              plan->x1_m[i], plan->y1_m[i])) {
            return true;
        }
    }
    return false;
}

static sf_floor_plan_t random_plan(rng_t *r, const int n)
{
    for (int i = 0; i < n; i++) {
        const double x = 60.0 * rng_uniform01(r), y = 40.0 * rng_uniform01(r), len = 0.2 + 6.0 * rng_uniform01(r);
        const double a = 6.283185307179586 * rng_uniform01(r);
        x0s[i] = (float)x;
        y0s[i] = (float)y;
        /* a third axis-aligned on the integer grid (cell edges, corners), the rest anywhere */
        if (i % 3 == 0) {
            x0s[i] = (float)floor(x);
            y0s[i] = (float)floor(y);
            x1s[i] = x0s[i] + (i % 2 ? 4.0f : 0.0f);
            y1s[i] = y0s[i] + (i % 2 ? 0.0f : 4.0f);
        } else {
            x1s[i] = (float)(x + len * cos(a));
            y1s[i] = (float)(y + len * sin(a));
        }
        floors[i] = (int16_t)(i % 5 == 0 ? 1 : 0);
    }
    return (sf_floor_plan_t){.n_walls = n, .x0_m = x0s, .y0_m = y0s, .x1_m = x1s, .y1_m = y1s, .floor = floors};
}

static void test_grid_equals_brute_force(void **state)
{
    (void)state;
    rng_t r = {.s = 0x1234567ULL};
    const sf_floor_plan_t plan = random_plan(&r, N_WALLS);
    const double cells[] = {0.5, 1.0, 2.0, 7.3};
    int hits = 0, total = 0;
    for (size_t c = 0; c < sizeof cells / sizeof cells[0]; c++) {
        const size_t bytes = sf_wall_grid_bytes(&plan, cells[c]);
        assert_true(bytes > 0 && bytes <= sizeof memory);
        sf_wall_grid_t g;
        assert_int_equal(sf_wall_grid_build(&g, &plan, cells[c], memory, bytes - 1), SF_EINVAL);
        assert_int_equal(sf_wall_grid_build(&g, &plan, cells[c], memory, bytes), SF_OK);
        assert_int_equal(g.n_floors, 2);
        assert_true(g.floors[0].floor == 0 && g.floors[1].floor == 1);
        for (int k = 0; k < 20000; k++) {
            const int16_t fl = (int16_t)(k % 4 == 0);
            double ax = -5.0 + 70.0 * rng_uniform01(&r), ay = -5.0 + 50.0 * rng_uniform01(&r);
            const double len = k % 7 == 0 ? 15.0 * rng_uniform01(&r) : 1.2 * rng_uniform01(&r);
            const double a = 6.283185307179586 * rng_uniform01(&r);
            double bx = ax + len * cos(a), by = ay + len * sin(a);
            if (k % 11 == 0) { /* on grid lines and through wall ends: the touching cases */
                ax = floor(ax);
                bx = ax;
                by = floor(by);
            }
            if (k % 13 == 0) {
                const int w = k % N_WALLS;
                bx = x0s[w];
                by = y0s[w];
            }
            const bool b = brute(&plan, fl, ax, ay, bx, by);
            assert_int_equal(sf_wall_grid_crosses(&g, fl, ax, ay, bx, by), b);
            hits += b;
            total++;
        }
    }
    printf("wall grid: %d of %d random steps cross a wall; grid = brute force on all\n", hits, total);
    assert_true(hits > total / 20 && hits < total - total / 20); /* both answers well exercised */
}

static void test_touching_and_collinear(void **state)
{
    (void)state;
    /* a wall from (0, 0) to (2, 0) */
    assert_true(sf_wall_segments_cross(1, -1, 1, 1, 0, 0, 2, 0));          /* proper */
    assert_true(sf_wall_segments_cross(1, -1, 1, 0, 0, 0, 2, 0));          /* ends on the wall */
    assert_false(sf_wall_segments_cross(1, 0, 1, 1, 0, 0, 2, 0));          /* starts on it, leaves */
    assert_true(sf_wall_segments_cross(-1, 0, 0.5, 0, 0, 0, 2, 0));        /* slides into it */
    assert_true(sf_wall_segments_cross(1, 0, 3, 0, 0, 0, 2, 0));           /* starts on it, slides along */
    assert_false(sf_wall_segments_cross(3, 0, 4, 0, 0, 0, 2, 0));          /* collinear, apart */
    assert_true(sf_wall_segments_cross(2, -1, 2, 1, 0, 0, 2, 0));          /* through its end point */
    assert_false(sf_wall_segments_cross(2.001, -1, 2.001, 1, 0, 0, 2, 0)); /* just past it */
    assert_false(sf_wall_segments_cross(1, -1, 1, -1, 0, 0, 2, 0));        /* zero-length step */
    /* a corner (walls (0,0)-(2,0) and (0,0)-(0,2)): a step from inside the L out through the corner
     * point is stopped, and so is every step that passes a hair beside it (no leak), while one outside
     * the L that grazes the corner from beyond is stopped only when it touches it */
    for (int k = -3; k <= 3; k++) {
        const double e = k * 1e-12;
        const bool a = sf_wall_segments_cross(1 + e, 1, -1, -1, 0, 0, 2, 0);
        const bool b = sf_wall_segments_cross(1 + e, 1, -1, -1, 0, 0, 0, 2);
        assert_true(a || b);
    }
    assert_true(sf_wall_segments_cross(-1, 1, 1, -1, 0, 0, 2, 0) || sf_wall_segments_cross(-1, 1, 1, -1, 0, 0, 0, 2));
    assert_false(sf_wall_segments_cross(-1.1, 1, 1, -1, 0, 0, 2, 0) || sf_wall_segments_cross(-1.1, 1, 1, -1, 0, 0, 0, 2));
}

static void test_no_walls_and_bad_walls(void **state)
{
    (void)state;
    const sf_floor_plan_t none = {0};
    assert_int_equal(sf_wall_grid_bytes(&none, 2.0), 4);
    assert_int_equal(sf_wall_grid_bytes(&none, 0.0), 0);
    assert_int_equal(sf_wall_grid_bytes(NULL, 2.0), 0);
    sf_wall_grid_t g;
    assert_int_equal(sf_wall_grid_build(&g, &none, 2.0, memory, 4), SF_OK);
    assert_false(sf_wall_grid_crosses(&g, 0, 0, 0, 10, 10));
    float x0[2] = {0, NAN}, y0[2] = {-1, 0}, x1[2] = {0, 1}, y1[2] = {1, 1};
    int16_t fl[2] = {3, 3};
    const sf_floor_plan_t plan = {.n_walls = 2, .x0_m = x0, .y0_m = y0, .x1_m = x1, .y1_m = y1, .floor = fl};
    assert_int_equal(sf_wall_grid_build(&g, &plan, 2.0, memory, sf_wall_grid_bytes(&plan, 2.0)), SF_OK);
    assert_int_equal(g.bad_segments, 1);
    assert_true(sf_wall_grid_crosses(&g, 3, -1, 0, 1, 0));
    assert_false(sf_wall_grid_crosses(&g, 2, -1, 0, 1, 0)); /* another floor has no walls */
    assert_false(sf_wall_grid_crosses(&g, 3, 50, 50, 60, 60)); /* far outside the grid */
}

/* A huge, sparse building: the cells grow so the grid fits SF_WALL_GRID_MAX_CELLS. */
static void test_cells_grow_to_fit(void **state)
{
    (void)state;
    float x0[2] = {0, 30000}, y0[2] = {0, 30000}, x1[2] = {1, 30001}, y1[2] = {0, 30000};
    int16_t fl[2] = {0, 0};
    const sf_floor_plan_t plan = {.n_walls = 2, .x0_m = x0, .y0_m = y0, .x1_m = x1, .y1_m = y1, .floor = fl};
    const size_t bytes = sf_wall_grid_bytes(&plan, 1.0);
    assert_true(bytes <= (size_t)(SF_WALL_GRID_MAX_CELLS + 100) * 4);
    static int32_t big[SF_WALL_GRID_MAX_CELLS + 100];
    sf_wall_grid_t g;
    assert_int_equal(sf_wall_grid_build(&g, &plan, 1.0, big, bytes), SF_OK);
    assert_true((int64_t)g.floors[0].nx * g.floors[0].ny <= SF_WALL_GRID_MAX_CELLS && g.floors[0].cell_m > 1.0);
    assert_true(sf_wall_grid_crosses(&g, 0, 30000.5, -1 + 30000, 30000.5, 30001));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_equals_brute_force),
        cmocka_unit_test(test_touching_and_collinear),
        cmocka_unit_test(test_no_walls_and_bad_walls),
        cmocka_unit_test(test_cells_grow_to_fit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
