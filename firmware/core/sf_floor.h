/* sf_floor.h — floor and vertical speed from the barometer.
 *
 * Height. Pressure p [Pa] → height by the hypsometric formula of the ICAO standard atmosphere,
 *     h_baro = 44330.77 m · (1 − (p / 101325 Pa)^0.190263),
 * whose slope is −0.0832 m/Pa (≈ −1/12 m/Pa, i.e. −dp/(ρg) with ρ = 1.225 kg/m³) at sea level and
 * steeper higher up (≈ −0.1 m/Pa at 2000 m), so one metre means one metre at any site altitude. Only
 * differences matter: height = h_baro + offset, where the offset is chosen at the first sample so that
 * the height equals the start floor's height (init_floor), and is re-chosen at each re-reference.
 *
 * Filters (continuous time, exact for any dt): h_f = first-order low-pass of height with
 * floor_height_tau_s; vertical speed v = first-order low-pass (floor_vspeed_tau_s) of Δh_f/Δt. Delay
 * ≈ the sum of the two time constants (2 s by default); noise of 2 Pa rms at 25 Hz gives |v| ≈ 0.02 m/s.
 *
 * Floors. A table of floor heights H[i] [m] for floors lowest_floor + i (strictly increasing, at most
 * SF_FLOOR_CAPACITY). Default (from params): uniform, H = floor_height_m · floor, for floors
 * init_floor − SF_FLOOR_DEFAULT_BELOW … up to the capacity. A site file replaces it with
 * sf_floor_set_heights.
 * Beyond the table's ends the floors go on as virtual floors, one end storey apart (floor_height_m for
 * a one-floor table): a walk started on a wrong floor number goes on counting the barometer's floor
 * changes past the building's end, and sf_floor_vote.h reads that as proof against the start floor.
 * Control (current floor f; candidate g = the floor whose height is nearest to the lead-corrected
 * height ĥ = h_f + v·floor_height_tau_s: a first-order low-pass lags a climb at speed v by v·τ exactly,
 * so ĥ crosses the mid-height when the body does, not a time constant later; SIL tour, stairs at
 * 0.25 m/s: ≈ 1 s earlier per change):
 *   - start a change: g ≠ f and |ĥ − H(f)| − |ĥ − H(g)| ≥ 2 · floor_hysteresis_m, i.e. ĥ lies
 *     floor_hysteresis_m beyond the mid-height between the two floors; while moving toward g
 *     (|v| ≥ floor_settle_vspeed_mps) the mid-height itself is enough: a dog-leg stair's landing sits
 *     exactly there, and the SIL truth counts it upper (hysteresis there cost 5 s per climb);
 *   - continue: the same g holds; any other candidate restarts the clock, f itself cancels it;
 *   - commit: after floor_confirm_ms, f ← g, and a re-reference is due;
 *   - at the floor: h_f nearer H(f) than the neighbour's height on its side by 2 · floor_hysteresis_m
 *     (sf_floor_at_floor; a half-way landing is not, a table storey 40 % off still is);
 *   - re-reference: once |v| < floor_settle_vspeed_mps and at the floor (arrived: not still climbing,
 *     not on a half-way landing), the offset is moved so h_f = H(f) exactly. So baro drift does not
 *     accumulate across floors;
 *   - drift: while no change is pending and |v| < floor_settle_vspeed_mps, h_f relaxes toward H(f)
 *     with floor_drift_tau_s (120 s), which absorbs weather drift on one floor (≈ 0.01 Pa/s) without
 *     touching a climb (stairs ≥ 0.2 m/s, elevators more);
 *   - leaving: when |v| first exceeds floor_settle_vspeed_mps, h_f of one to two filter delays before
 *     (τ_h + τ_v: the climb had not moved it yet) is taken as H(f) if it is within the drift's largest
 *     lag (floor_weather_max_hpa_per_h · floor_drift_tau_s, 0.83 m): the relaxation lags a weather
 *     trend by rate · τ (0.15–0.4 m on the SIL tours), and the climb counts from the floor. A larger gap
 *     is a pause part-way down a stair (gsd Trial51), not a floor.
 *
 * Shift (sf_floor_shift): the floor number moves by k floors while the body stays where it is (the
 * floor vote found the start floor wrong): h_f − H(f) is kept, or, for a change the barometer made up
 * (beyond every floor of the building), the altimeter is re-referenced at once.
 *
 * Bad data: a non-finite pressure or one outside [SF_FLOOR_MIN_PA, SF_FLOOR_MAX_PA] is counted in `bad`
 * and skipped; a sample at or before the previous time in `backwards`; a gap longer than
 * floor_max_gap_ms restarts the filters at the new height (offset and floor kept) and counts in `gaps`.
 *
 * Errors: sf_floor_set_heights returns SF_OK or SF_EINVAL (NULL, n_floors outside
 * [1, SF_FLOOR_CAPACITY], a height not finite or not strictly above the one below, or a table that
 * would leave int16 floor numbers). Everything else cannot fail.
 * Cost (callgrind, x86-64 -O3, `stridefix bench perf`'s sensors walk): ≈ 275 instructions per
 * sf_floor_update (≈ 380 with a pow() per sample: the pressure's height is now a series around the
 * last pressure that needed one, sf_floor_baro_height_m, a pow per ≈ 8.5 m of climb, within 2e-9 m of
 * sf_floor_pressure_to_height_m); the low-pass gains are remembered per (dt, τ)
 * (sf_lp_gain: an expm1 only when the rate changes) and the nearest floor is a bisection,
 * O(log n_floors) (the 64-floor scan was ≈ 800). Memory: sizeof(sf_floor_t) = 736 B on x86-64
 * (i686 not rechecked) (at most 744 B, checked). No heap, no I/O, no clock. */
#ifndef SF_FLOOR_H
#define SF_FLOOR_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_math.h"
#include "sf_params.h"

#define SF_FLOOR_CAPACITY 64
#define SF_FLOOR_DEFAULT_BELOW 16 /* default table: this many floors below init_floor */
#define SF_FLOOR_MIN_PA 30000.0   /* ≈ 9 km altitude */
#define SF_FLOOR_MAX_PA 120000.0  /* deep mine; beyond is a broken sensor */
_Static_assert(SF_FLOOR_CAPACITY > SF_FLOOR_DEFAULT_BELOW, "default table needs floors above the start");
_Static_assert(SF_FLOOR_CAPACITY <= 1000, "floor numbers are int16");

typedef struct {
    /* table */
    double height_m[SF_FLOOR_CAPACITY];
    int32_t n_floors;
    int16_t lowest_floor;
    double storey_m; /* beyond a one-floor table (floor_height_m) */
    /* altimeter */
    bool started;
    int64_t last_t_us;
    double offset_m;   /* height = h_baro + offset */
    double height_m_f; /* low-passed height h_f [m] */
    double vspeed_mps; /* low-passed vertical speed v [m/s] */
    /* control */
    int16_t floor;          /* current floor f */
    int16_t candidate;      /* candidate g while a change is pending */
    bool change_pending;
    int64_t candidate_since_us;
    bool reref_due;
    bool was_settled;        /* the previous sample was settled */
    bool stood_valid;        /* stood_height_m is from this stay on the floor */
    double stood_height_m;   /* h_f one to two filter delays ago, while settled */
    int64_t recent_t_us;     /* the newer snapshot */
    double recent_height_m;
    /* the low-pass gains of the last (dt, τ): one expm1 per rate change, not three per sample */
    sf_lp_gain_t gain_height, gain_vspeed, gain_drift;
    /* the pressure → height series' reference (sf_floor_baro_height_m): r [Pa] (0: none yet), 1/r,
     * (r/p0)^0.190263 */
    double baro_ref_pa, baro_ref_inv_pa, baro_ref_pow;
    /* counters, never decrease */
    uint32_t changes, rereferences, shifts, gaps, backwards, bad;
} sf_floor_t;
_Static_assert(sizeof(sf_floor_t) <= 744, "sf_floor.h promises at most 744 B");

/* Default uniform table from floor_height_m around init_floor; current floor = init_floor. */
void sf_floor_init(sf_floor_t *f, const sf_params_t *p);

/* Replaces the table: floor_height_m[i] is the height of floor lowest_floor + i. The current floor is
 * kept (moved to the nearest floor of the table if outside it) and, once started, the altimeter is
 * re-referenced at once: the user is taken to be on that floor now. */
int sf_floor_set_heights(sf_floor_t *f, const double *floor_height_m, int n_floors, int16_t lowest_floor);

/* Consumes one barometer sample. */
void sf_floor_update(sf_floor_t *f, const sf_params_t *p, int64_t t_us, double pressure_pa);

/* The current floor. */
int16_t sf_floor_current(const sf_floor_t *f);

/* The low-passed vertical speed [m/s], up positive; 0 before two samples. */
double sf_floor_vertical_speed_mps(const sf_floor_t *f);

/* The low-passed height [m] in the floor table's datum. */
double sf_floor_height_m(const sf_floor_t *f);

/* Whether the height is at the current floor: started, no change pending, h_f nearer the floor's
 * height than the neighbour's on that side by 2 · floor_hysteresis_m (not on a landing half-way up). */
bool sf_floor_at_floor(const sf_floor_t *f, const sf_params_t *p);

/* At the floor and still: |vertical speed| below floor_settle_vspeed_mps too (not on the stairs, not in
 * a moving lift). */
bool sf_floor_settled(const sf_floor_t *f, const sf_params_t *p);

/* Renumbers the current floor by delta floors (the body stays): h_f − H(floor) is kept, or with
 * rereference_now the altimeter is re-referenced to the new floor's height at once. Any pending change
 * is cancelled. Table floors and virtual floors alike. */
void sf_floor_shift(sf_floor_t *f, int32_t delta, bool rereference_now);

/* ICAO standard-atmosphere height for a pressure [Pa → m]. */
double sf_floor_pressure_to_height_m(double pressure_pa);

/* sf_floor_pressure_to_height_m as sf_floor_update computes it: a series around the last pressure that
 * needed a pow (the reference in f, updated here), within 2e-9 m of the pow form (sf_floor.c). */
double sf_floor_baro_height_m(sf_floor_t *f, double pressure_pa);

#endif
