/* test_floor_nearest.c — intrusive (includes sf_floor.c for its static nearest_floor): the bisection
 * gives what the linear scan it replaced gave (the first floor strictly nearest), on seeded random
 * tables of 1–64 floors with storeys of 1–20 m, at heights anywhere in the table, exactly on a floor
 * and exactly half-way between two (the ties the scan breaks toward the lower floor). */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "../../firmware/core/sf_floor.c"
#include "sf_test_rng.h"

/* The scan sf_floor.c had before (inside the table): the first index strictly nearest. */
static int16_t nearest_by_scan(const sf_floor_t *const f, const double h_m)
{
    int32_t best = 0;
    for (int32_t i = 1; i < f->n_floors; i++) {
        if (fabs(h_m - f->height_m[i]) < fabs(h_m - f->height_m[best])) {
            best = i;
        }
    }
    return (int16_t)(f->lowest_floor + best);
}

static void test_bisection_equals_scan(void **state)
{
    (void)state;
    rng_t rng = {.s = 16};
    int checked = 0;
    for (int table = 0; table < 2000; table++) {
        sf_floor_t f = {0};
        f.n_floors = 1 + (int32_t)(rng_uniform01(&rng) * SF_FLOOR_CAPACITY);
        if (f.n_floors > SF_FLOOR_CAPACITY) {
            f.n_floors = SF_FLOOR_CAPACITY;
        }
        f.lowest_floor = (int16_t)(-3 + table % 7);
        f.storey_m = 3.5;
        double h = -20.0 + 40.0 * rng_uniform01(&rng);
        for (int32_t i = 0; i < f.n_floors; i++) {
            f.height_m[i] = h;
            h += table % 5 == 0 ? 3.0 : 1.0 + 19.0 * rng_uniform01(&rng); /* even tables tie often */
        }
        const double lo = f.height_m[0], hi = f.height_m[f.n_floors - 1];
        for (int k = 0; k < 50; k++) {
            const int32_t i = (int32_t)(rng_uniform01(&rng) * (double)f.n_floors) % f.n_floors;
            const int32_t j = i + 1 < f.n_floors ? i + 1 : i;
            const double probes[3] = {lo + (hi - lo) * rng_uniform01(&rng), f.height_m[i],
                                      0.5 * (f.height_m[i] + f.height_m[j])};
            for (int m = 0; m < 3; m++) {
                assert_int_equal(nearest_floor(&f, probes[m]), nearest_by_scan(&f, probes[m]));
                checked++;
            }
        }
    }
    assert_int_equal(checked, 2000 * 50 * 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bisection_equals_scan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
