/* test_pace.c — sf_pace: the wall time a --speed replay waits before each input item.
 *
 * GIVEN items recorded at known input times and a wall clock the test moves, THEN each item is due at
 * origin wall time + (input time − origin input time) / speed: the wait is what is left of that, 0 once
 * due; pacing off never waits; a backwards input time starts a new origin; a whole recording handled
 * without work takes its span / speed. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "sf_pace.h"

#define T0 1700000000000000LL /* an input time: host µs since the epoch, as candump stamps */
#define W0 5000000LL          /* a monotonic wall time */

static void off_never_waits(void **state)
{
    (void)state;
    sf_pace_t p;
    const double speeds[] = {0.0, -1.0, NAN, INFINITY};
    for (size_t i = 0; i < sizeof speeds / sizeof speeds[0]; i++) {
        sf_pace_init(&p, speeds[i]);
        assert_false(sf_pace_on(&p));
        assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0);
        assert_int_equal(sf_pace_wait_us(&p, T0 + 60000000, W0), 0);
    }
}

static void real_time_waits_the_input_gap(void **state)
{
    (void)state;
    sf_pace_t p;
    sf_pace_init(&p, 1.0);
    assert_true(sf_pace_on(&p));
    assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0); /* the origin */
    /* 10 ms of input later, 2 ms of wall time spent on the first item: 8 ms left */
    assert_int_equal(sf_pace_wait_us(&p, T0 + 10000, W0 + 2000), 8000);
    /* an item exactly due, and one late (the work took longer than the input's gap): no wait */
    assert_int_equal(sf_pace_wait_us(&p, T0 + 20000, W0 + 20000), 0);
    assert_int_equal(sf_pace_wait_us(&p, T0 + 30000, W0 + 45000), 0);
    /* late items do not move the timeline: the next one is due at its own time, not 15 ms later */
    assert_int_equal(sf_pace_wait_us(&p, T0 + 50000, W0 + 45000), 5000);
}

static void speed_divides_input_time(void **state)
{
    (void)state;
    const struct {
        double speed;
        int64_t input_dt_us, wall_dt_us, wait_us;
    } rows[] = {
        {20.0, 1000000, 0, 50000},      /* 1 s of input at 20x: 50 ms */
        {20.0, 1000000, 30000, 20000},  /* 30 ms of it already spent */
        {50.0, 333000000, 0, 6660000},  /* a 333 s walk at 50x: 6.66 s */
        {0.5, 1000000, 0, 2000000},     /* half speed: twice as long */
        {3.0, 1000000, 0, 333334},      /* not whole microseconds: rounded up, never early */
        {1000.0, 7, 0, 1},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        sf_pace_t p;
        sf_pace_init(&p, rows[i].speed);
        assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0);
        assert_int_equal(sf_pace_wait_us(&p, T0 + rows[i].input_dt_us, W0 + rows[i].wall_dt_us), rows[i].wait_us);
    }
}

static void backwards_input_time_starts_a_new_origin(void **state)
{
    (void)state;
    sf_pace_t p;
    sf_pace_init(&p, 10.0);
    assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0);
    assert_int_equal(sf_pace_wait_us(&p, T0 + 100000, W0), 10000);
    /* a recording appended from an hour earlier: not a burst, paced from here */
    const int64_t t1 = T0 - 3600000000LL;
    assert_int_equal(sf_pace_wait_us(&p, t1, W0 + 10000), 0);
    assert_int_equal(p.restarts, 1);
    assert_int_equal(sf_pace_wait_us(&p, t1 + 100000, W0 + 10000), 10000);
    /* equal input times are not backwards: both due at once */
    assert_int_equal(sf_pace_wait_us(&p, t1 + 100000, W0 + 20000), 0);
    assert_int_equal(p.restarts, 1);
}

static void a_long_silence_is_waited_out_and_bounded(void **state)
{
    (void)state;
    sf_pace_t p;
    sf_pace_init(&p, 0.001);
    assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0);
    /* 10 min of silence at 0.001x is 10^4 min: over the bound, so the bound */
    assert_int_equal(sf_pace_wait_us(&p, T0 + 600000000000LL, W0), SF_PACE_WAIT_MAX_US);
    sf_pace_init(&p, 2.0);
    assert_int_equal(sf_pace_wait_us(&p, T0, W0), 0);
    assert_int_equal(sf_pace_wait_us(&p, T0 + 600000000, W0), 300000000); /* 10 min at 2x: 5 min */
}

/* A 100 Hz recording of 60 s handled with no work and each wait slept exactly: the last item is
 * handled span / speed after the first, and every item at its own due time. */
static void a_recording_takes_its_span_over_speed(void **state)
{
    (void)state;
    sf_pace_t p;
    sf_pace_init(&p, 20.0);
    int64_t wall = W0;
    for (int64_t i = 0; i <= 6000; i++) {
        const int64_t t = T0 + i * 10000;
        wall += sf_pace_wait_us(&p, t, wall);
        assert_int_equal(wall, W0 + i * 500); /* 10 ms of input: 0.5 ms of wall time */
    }
    assert_int_equal(wall - W0, 3000000); /* 60 s at 20x: 3 s */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(off_never_waits),
        cmocka_unit_test(real_time_waits_the_input_gap),
        cmocka_unit_test(speed_divides_input_time),
        cmocka_unit_test(backwards_input_time_starts_a_new_origin),
        cmocka_unit_test(a_long_silence_is_waited_out_and_bounded),
        cmocka_unit_test(a_recording_takes_its_span_over_speed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
