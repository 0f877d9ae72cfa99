/* sf_floor_vote.c — see sf_floor_vote.h for the model. */
#include "sf_floor_vote.h"

#include <math.h>
#include <stddef.h>

#include "sf_assert.h"

static int32_t highest(const sf_floor_vote_t *const v)
{
    return (int32_t)v->lowest_floor + v->n_floors - 1;
}

static int32_t clamp_floor(const sf_floor_vote_t *const v, const int32_t floor)
{
    return floor < v->lowest_floor ? v->lowest_floor : (floor > highest(v) ? highest(v) : floor);
}

static bool feasible(const sf_floor_vote_t *const v, const int32_t s)
{
    return s + v->d_min >= v->lowest_floor && s + v->d_max <= highest(v);
}

static int32_t distance(const int32_t a, const int32_t b)
{
    return a > b ? a - b : b - a;
}

static double score_of(const sf_floor_vote_t *const v, const int32_t s)
{
    return v->score[s - v->lowest_floor];
}

/* The feasible s with the highest score (ties: nearest the current s, then the lower); the current s
 * when none is feasible. *runner_up: the best score among the other feasible s (−1 if none). */
static int32_t leader(const sf_floor_vote_t *const v, double *const runner_up)
{
    int32_t best = v->start;
    bool found = false;
    for (int32_t s = v->lowest_floor; s <= highest(v); s++) {
        if (!feasible(v, s)) {
            continue;
        }
        const double sc = score_of(v, s);
        const bool better = !found || sc > score_of(v, best) ||
                            (sc == score_of(v, best) && distance(s, v->start) < distance(best, v->start));
        if (better) {
            best = s;
            found = true;
        }
    }
    *runner_up = -1.0;
    for (int32_t s = v->lowest_floor; s <= highest(v); s++) {
        if (s != best && feasible(v, s)) {
            *runner_up = fmax(*runner_up, score_of(v, s));
        }
    }
    return best;
}

/* s ← to; the caller renumbers its floor by the same amount (d is unchanged). */
static int32_t move_start(sf_floor_vote_t *const v, const int32_t to)
{
    const int32_t delta = to - v->start;
    if (delta != 0) {
        v->start = (int16_t)to;
        v->switches++;
    }
    return delta;
}

void sf_floor_vote_init(sf_floor_vote_t *const v, const int16_t lowest_floor, const int32_t n_floors,
                        const int16_t baro_floor, const bool pinned)
{
    *v = (sf_floor_vote_t){0};
    v->lowest_floor = lowest_floor;
    v->n_floors = n_floors < 1 ? 1 : (n_floors > SF_FLOOR_CAPACITY ? SF_FLOOR_CAPACITY : n_floors);
    v->start = (int16_t)clamp_floor(v, baro_floor);
    v->pinned = pinned;
    v->decided = pinned;
    v->d_min = v->d_max = (int32_t)baro_floor - v->start;
}

int32_t sf_floor_vote_baro(sf_floor_vote_t *const v, const int16_t baro_floor, bool *const rereference)
{
    *rereference = false;
    const int32_t d = (int32_t)baro_floor - v->start;
    v->d_min = d < v->d_min ? d : v->d_min;
    v->d_max = d > v->d_max ? d : v->d_max;
    if (feasible(v, v->start)) {
        return 0;
    }
    double runner_up;
    const int32_t best = leader(v, &runner_up);
    if (feasible(v, best)) { /* proof: the walk cannot have started on s */
        v->proofs++;
        return move_start(v, best);
    }
    /* spurious: no start fits; restart the count with the floor back inside the table */
    v->spurious++;
    for (int32_t i = 0; i < v->n_floors; i++) {
        v->score[i] = 0.0;
    }
    *rereference = true;
    const int32_t inside = clamp_floor(v, baro_floor);
    v->d_min = v->d_max = inside - v->start;
    return inside - baro_floor; /* s kept: the barometric floor moves, not the start */
}

void sf_floor_vote_renumber(sf_floor_vote_t *const v, const int32_t shift)
{
    SF_ASSERT(v != NULL);
    if (shift != 0) {
        v->start = (int16_t)clamp_floor(v, (int32_t)v->start + shift);
        v->switches++;
    }
}

int32_t sf_floor_vote_fix(sf_floor_vote_t *const v, const sf_params_t *const p, const sf_fix_t *const fix,
                          const int16_t baro_floor, const bool settled)
{
    SF_ASSERT(v != NULL && p != NULL && fix != NULL);
    if (fix->method == sf_fix_gnss || !settled) { /* a GNSS fix knows no floor */
        return 0;
    }
    const int32_t s = (int32_t)fix->floor - ((int32_t)baro_floor - v->start);
    if (s < v->lowest_floor || s > highest(v)) {
        return 0; /* the fix's floor and the barometer agree on no start in the building */
    }
    const double ref = (double)p->fingerprint_accuracy_ref_aps;
    /* a landmark's floor (or a port recalibration's) is known, not guessed: it alone decides (a full margin) */
    const double w = sf_fix_is_known_position(fix->method) ? p->floor_vote_margin : fmin(1.0, (double)fix->n_ap_used / ref);
    v->score[s - v->lowest_floor] += w;
    v->votes++;
    if (v->pinned) {
        return 0;
    }
    double runner_up;
    const int32_t best = leader(v, &runner_up);
    const double margin = p->floor_vote_margin;
    if (!v->decided) {
        v->decided = score_of(v, best) - fmax(runner_up, 0.0) >= margin;
        return move_start(v, best);
    }
    if (best != v->start && score_of(v, best) >= score_of(v, v->start) + margin) {
        return move_start(v, best);
    }
    return 0;
}
