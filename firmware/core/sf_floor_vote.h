/* sf_floor_vote.h — which floor number the walk started on: a vote of the fixes' floors (Wi-Fi fixes,
 * landmarks, loud BLE beacons; GNSS knows no floor), held against what the barometer says the walk did
 * since.
 *
 * The barometer (sf_floor.h) owns floor *changes*: it counts floors up and down from the start, d(t) =
 * its floor − s, where s is the start floor in use. The fixes own the floor *number*, but a fix's floor
 * is a classifier's guess (a radio map may have no reference point of the right floor nearby), so no
 * one scan decides anything. Each hypothesis "the walk started on floor s" (every floor of the site
 * table) has
 *   - a score: Σ of the weights of the settled fixes that agree with it, i.e. whose floor g = s + d at
 *     their time (w = min(1, n_ap_used / fingerprint_accuracy_ref_aps): a fix from few APs is the weaker
 *     guess, as for its accuracy; a landmark w = floor_vote_margin: its floor is known, it decides);
 *     fixes while the altimeter is not settled (on stairs, in a moving lift, a change pending) do not
 *     vote, d is then unsure;
 *   - feasibility: s + d stayed inside the building's floors the whole time, s + d_min ≥ lowest and
 *     s + d_max ≤ highest. A walk that went two floors down from s cannot have started on the lowest
 *     floor, whatever the fixes say. This is a proof, the score only a vote.
 * Control:
 *   - start: s = init_floor (clamped to the table), undecided; while undecided, s follows the leader
 *     (the feasible s with the highest score; ties: nearest the current s, then the lower), and the
 *     vote is decided once the leader leads every other feasible s by floor_vote_margin;
 *   - continue (decided): s moves to the leader only when its score passes s's by floor_vote_margin
 *     (a run of consistent fixes on another floor with the barometer flat: the reference was wrong);
 *   - proof: s infeasible → s = the leader among the feasible at once, decided or not;
 *   - spurious change: no s feasible (the barometer went further than the building is tall: weather,
 *     a door, a wrong table) → the range is restarted at the current d and the current floor is moved
 *     back into the table (the altimeter re-referenced there); the scores, cast in the old count, are
 *     cleared;
 *   - pinned (truth-initialised runs, init_use_config_pose: the start floor is given): only the proof
 *     and the spurious-change rule move s;
 *   - renumbered from outside (the multi-scheme controller identified a floor context and moved the
 *     barometric floor there, sf_estimator.c): s moves with it, d and the scores stay. Without
 *     this the vote would read the renumbering as a climb (d ± the shift) and refuse, as infeasible,
 *     every later fix on the floor the walker is really on; with it those fixes vote on as before and
 *     move s back when they lead by the margin.
 * Each call returns by how many floors the caller must renumber its barometric floor (sf_floor_shift):
 * the body stays where it is, its floor number changes with s.
 *
 * Errors: none (void or a shift). Bad data (a fix floor outside int16 arithmetic) cannot occur: floors
 * are int16 and d is bounded by the table plus SF_FLOOR_CAPACITY virtual floors (sf_floor.h).
 * Cost: O(n_floors) per call. Memory: sizeof(sf_floor_vote_t) = 552 B on x86-64 (at most 576 B,
 * checked). No heap, no I/O, no clock. */
#ifndef SF_FLOOR_VOTE_H
#define SF_FLOOR_VOTE_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_floor.h"
#include "sf_params.h"
#include "sf_types.h"

typedef struct {
    int16_t lowest_floor; /* the site table's floors */
    int32_t n_floors;
    int16_t start;        /* s: the start floor in use */
    bool decided;
    bool pinned;
    int32_t d_min, d_max; /* range of d = barometric floor − s since the start (or the last restart) */
    double score[SF_FLOOR_CAPACITY]; /* agreeing fix weight for s = lowest_floor + i */
    /* counters, never decrease */
    uint32_t votes, switches, proofs, spurious;
} sf_floor_vote_t;
_Static_assert(sizeof(sf_floor_vote_t) <= 576, "sf_floor_vote.h promises at most 576 B");

/* A vote over the floors lowest_floor … lowest_floor + n_floors − 1 (n_floors clamped to
 * [1, SF_FLOOR_CAPACITY]); s = baro_floor (the barometer's start floor, clamped to the table). */
void sf_floor_vote_init(sf_floor_vote_t *v, int16_t lowest_floor, int32_t n_floors, int16_t baro_floor,
                        bool pinned);

/* After a barometer sample: the barometric floor now. Returns the renumbering for sf_floor_shift and
 * sets *rereference (the spurious-change rule: re-reference at once). */
int32_t sf_floor_vote_baro(sf_floor_vote_t *v, int16_t baro_floor, bool *rereference);

/* The caller renumbered its barometric floor by shift for a reason of its own (the body did not
 * move): s moves by the same amount (clamped to the table), d and the scores are kept. */
void sf_floor_vote_renumber(sf_floor_vote_t *v, int32_t shift);

/* One fix (Wi-Fi: votes; other methods carry no floor evidence here) while the barometer says
 * baro_floor and is settled or not. Returns the renumbering for sf_floor_shift (h_f − H kept). */
int32_t sf_floor_vote_fix(sf_floor_vote_t *v, const sf_params_t *p, const sf_fix_t *fix, int16_t baro_floor,
                          bool settled);

#endif
