/* test_floor_vote.c — the start-floor vote: a majority of fixes decides, one scan never flips a
 * decided vote, weights follow the APs used, the building's floors prove a start wrong (the gsd
 * Trial51 story), a change beyond the building is spurious, a truth-initialised start is pinned,
 * fixes on the stairs do not vote, a renumbering from outside (the controller) is not a climb. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "sf_floor_vote.h"
#include "sf_params.h"

static sf_fix_t wifi_on(const int16_t floor, const int16_t n_ap)
{
    return (sf_fix_t){.t_us = 1, .method = sf_fix_wifi, .floor = floor, .accuracy_m = 3.0, .n_ap_used = n_ap};
}

/* Offers one fix at barometric floor *baro and applies the renumbering as the estimator does. */
static int32_t offer(sf_floor_vote_t *v, const sf_params_t *p, int16_t *baro, const int16_t fix_floor,
                     const int16_t n_ap, const bool settled)
{
    const sf_fix_t fx = wifi_on(fix_floor, n_ap);
    const int32_t k = sf_floor_vote_fix(v, p, &fx, *baro, settled);
    *baro = (int16_t)(*baro + k);
    return k;
}

static int32_t baro_to(sf_floor_vote_t *v, int16_t *baro, const int16_t floor, bool *reref)
{
    *baro = floor;
    const int32_t k = sf_floor_vote_baro(v, *baro, reref);
    *baro = (int16_t)(*baro + k);
    return k;
}

static void test_majority_decides(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 0;
    sf_floor_vote_init(&v, -2, 5, baro, false); /* floors -2 … 2, barometer starts on init.floor 0 */
    /* undecided: the leader is followed at once (the first fix says 2) */
    assert_int_equal(offer(&v, &p, &baro, 2, 6, true), 2);
    assert_int_equal(baro, 2);
    assert_false(v.decided);
    /* a fix on 1: a tie, the current start stays; two more on 2 make a lead of 3 − 1 = 2 < 3 */
    assert_int_equal(offer(&v, &p, &baro, 1, 6, true), 0);
    offer(&v, &p, &baro, 2, 6, true);
    offer(&v, &p, &baro, 2, 6, true);
    assert_false(v.decided);
    /* a fourth on 2: lead 4 − 1 = 3 = floor_vote_margin, decided */
    offer(&v, &p, &baro, 2, 6, true);
    assert_true(v.decided);
    assert_int_equal(v.start, 2);
    assert_int_equal(baro, 2);
    assert_int_equal(v.votes, 5);
}

static void test_one_scan_never_flips(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 0;
    sf_floor_vote_init(&v, 0, 3, baro, false);
    for (int i = 0; i < 3; i++) {
        offer(&v, &p, &baro, 0, 8, true);
    }
    assert_true(v.decided);
    /* the barometer climbs one floor: fixes on 1 agree with the start 0 */
    bool reref;
    assert_int_equal(baro_to(&v, &baro, 1, &reref), 0);
    offer(&v, &p, &baro, 1, 8, true);
    assert_true(v.score[0] == 4.0);
    /* a run of fixes on 2 while the barometer says 1: the reference was wrong once they lead by 3 */
    for (int i = 0; i < 6; i++) {
        assert_int_equal(offer(&v, &p, &baro, 2, 8, true), 0);
        assert_int_equal(baro, 1);
    }
    assert_int_equal(offer(&v, &p, &baro, 2, 8, true), 1); /* 7 ≥ 4 + 3 */
    assert_int_equal(baro, 2);
    assert_int_equal(v.start, 1);
    assert_int_equal(v.switches, 1);
}

static void test_weights_follow_aps(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p); /* fingerprint_accuracy_ref_aps = 6 */
    sf_floor_vote_t v;
    int16_t baro = 1;
    sf_floor_vote_init(&v, 0, 2, baro, false);
    /* three-AP fixes weigh 0.5: six of them on floor 0 to decide */
    for (int i = 0; i < 5; i++) {
        offer(&v, &p, &baro, 0, 3, true);
        assert_false(v.decided);
    }
    offer(&v, &p, &baro, 0, 3, true);
    assert_true(v.decided);
    assert_true(v.score[0] == 3.0);
    assert_int_equal(baro, 0);
    /* a GNSS fix carries no floor; neither does a fix while the altimeter is not settled */
    sf_fix_t g = wifi_on(1, 20);
    g.method = sf_fix_gnss;
    assert_int_equal(sf_floor_vote_fix(&v, &p, &g, baro, true), 0);
    assert_int_equal(offer(&v, &p, &baro, 1, 20, false), 0);
    assert_int_equal(v.votes, 6);
}

/* gsd Trial51 (leave one out): the fold's map has no floor 0 or −1 reference point near the route,
 * so every fix says −2; the walk goes 0 → −1 → −2. The building proves the start wrong twice. */
static void test_the_building_proves_the_start(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 0;
    sf_floor_vote_init(&v, -2, 3, baro, false);
    for (int i = 0; i < 10; i++) {
        offer(&v, &p, &baro, -2, 12, true);
    }
    assert_true(v.decided);
    assert_int_equal(baro, -2);
    /* one floor down: below the lowest floor, so the start was not −2; −1 and 0 are tied at 0 votes,
     * the nearest (−1) is taken: the walk is on −2 now */
    bool reref;
    assert_int_equal(baro_to(&v, &baro, -3, &reref), 1);
    assert_false(reref);
    assert_int_equal(baro, -2);
    assert_int_equal(v.start, -1);
    for (int i = 0; i < 5; i++) {
        offer(&v, &p, &baro, -2, 12, true); /* agree with start −1 now */
    }
    /* a second floor down: only start 0 is left, whatever the votes */
    assert_int_equal(baro_to(&v, &baro, -3, &reref), 1);
    assert_int_equal(baro, -2);
    assert_int_equal(v.start, 0);
    assert_int_equal(v.proofs, 2);
    /* back up on floor 0, the fixes still say −2: start −2 is infeasible for good */
    assert_int_equal(baro_to(&v, &baro, 0, &reref), 0);
    for (int i = 0; i < 30; i++) {
        assert_int_equal(offer(&v, &p, &baro, -2, 12, true), 0);
    }
    assert_int_equal(baro, 0);
    assert_int_equal(v.d_min, -2);
    assert_int_equal(v.d_max, 0);
}

static void test_change_beyond_the_building_is_spurious(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 3;
    sf_floor_vote_init(&v, 3, 1, baro, false); /* a one-floor site (msindoor) */
    offer(&v, &p, &baro, 3, 10, true);
    bool reref;
    assert_int_equal(baro_to(&v, &baro, 4, &reref), -1); /* no start fits: back to 3, re-referenced */
    assert_true(reref);
    assert_int_equal(baro, 3);
    assert_int_equal(v.start, 3);
    assert_int_equal(v.spurious, 1);
    assert_true(v.score[0] == 0.0); /* cast in the old count: cleared */
    assert_int_equal(v.d_min, 0);
    assert_int_equal(v.d_max, 0);
    /* with the range restarted, the next samples are fine */
    assert_int_equal(baro_to(&v, &baro, 3, &reref), 0);
    assert_false(reref);
}

static void test_pinned_start(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 0;
    sf_floor_vote_init(&v, -2, 3, baro, true); /* truth-initialised on floor 0 */
    assert_true(v.decided);
    for (int i = 0; i < 50; i++) {
        assert_int_equal(offer(&v, &p, &baro, -2, 12, true), 0);
    }
    assert_int_equal(baro, 0);
    assert_true(v.score[0] == 50.0); /* still counted, for the record */
    /* but the proof still holds: a start of 0 cannot climb above 0; the votes then pick among the
     * starts left (−2 with 50 votes over −1 with none) */
    bool reref;
    assert_int_equal(baro_to(&v, &baro, 1, &reref), -2);
    assert_int_equal(baro, -1);
    assert_int_equal(v.start, -2);
}

/* A basement walk (ipin2023 Trial24): the controller's CLS named floor 0 from one beacon heard across
 * the slab and renumbered the barometric floor by +2. The vote took that for a two-floor climb, so every
 * later Wi-Fi fix on −2 asked for a start of −4, outside the building, and was dropped: floor 0 for the
 * whole walk. Renumbered with the barometer, the fixes on −2 keep voting and win. */
static void test_renumbering_is_not_a_climb(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_vote_t v;
    int16_t baro = 0;
    sf_floor_vote_init(&v, -2, 3, baro, false); /* floors -2 … 0 */
    assert_int_equal(offer(&v, &p, &baro, -2, 8, true), -2); /* the first fix: -2 */
    assert_int_equal(baro, -2);
    /* the controller renumbers to 0 (the caller shifts its barometric floor, then tells the vote) */
    baro = 0;
    sf_floor_vote_renumber(&v, 2);
    assert_int_equal(v.start, 0);
    assert_int_equal(v.d_min, 0);
    assert_int_equal(v.d_max, 0);
    bool reref;
    assert_int_equal(baro_to(&v, &baro, 0, &reref), 0); /* the same floor: no climb, nothing proven */
    assert_false(reref);
    /* fixes on -2 still vote for the start -2 (they would ask for -4 had the shift been a climb) */
    int32_t moved = 0;
    for (int i = 0; i < 3; i++) {
        moved += offer(&v, &p, &baro, -2, 8, true);
    }
    assert_int_equal(moved, -2);
    assert_int_equal(baro, -2);
    assert_int_equal(v.start, -2);
    assert_true(v.decided);
    /* a renumbering past the table is clamped into it */
    sf_floor_vote_renumber(&v, -5);
    assert_int_equal(v.start, -2);
}

static void test_init_clamps_into_the_table(void **state)
{
    (void)state;
    sf_floor_vote_t v;
    sf_floor_vote_init(&v, -2, 3, 7, false);
    assert_int_equal(v.start, 0);
    assert_int_equal(v.d_min, 7); /* the barometer is 7 above the start: the first sample proves it */
    bool reref;
    int16_t baro = 7;
    baro_to(&v, &baro, 7, &reref);
    assert_true(reref);
    assert_int_equal(baro, 0);
    sf_floor_vote_init(&v, 0, 1000, 0, false);
    assert_int_equal(v.n_floors, SF_FLOOR_CAPACITY);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_majority_decides),
        cmocka_unit_test(test_one_scan_never_flips),
        cmocka_unit_test(test_weights_follow_aps),
        cmocka_unit_test(test_the_building_proves_the_start),
        cmocka_unit_test(test_change_beyond_the_building_is_spurious),
        cmocka_unit_test(test_pinned_start),
        cmocka_unit_test(test_renumbering_is_not_a_climb),
        cmocka_unit_test(test_init_clamps_into_the_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
