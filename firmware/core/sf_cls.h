/* sf_cls.h — the coarse localization subsystem (CLS) of the multi-scheme controller, after Jäger,
 * Süß, Becker §III-B (Fig. 4; ../shared/papers/jaeger-suess-becker-auto-adaptive-dr.md §1.4, §1.6),
 * and the context map's geometry the controller asks about (sf_controller.h).
 *
 * The CLS has no radio map and no fusion: it only asks whether a context's beacon constellation (its
 * context determination descriptor, CDD: Wi-Fi APs or BLE beacons, sf_context_map_t.cdd_*) is heard,
 * or whether a GNSS fix is good enough for a context whose CDD is GNSS (outdoors, "a special floor").
 * A reading identifies context i when at least cdd_min_hits[i] of its members are heard at their
 * cdd_min_dbm or louder (each member counted once); a GNSS fix when its accuracy is at most the
 * caller's bound. The CLS searches a set of candidate contexts, a 64-bit mask (bit i: context i):
 * every context in unlimited mode (sf_cls_all), a port's neighbourhood in limited mode
 * (sf_cls_neighbourhood); readings outside a search, and identifications of contexts outside the
 * candidates, leave no evidence. Evidence per context is the latest identification's time, hits and
 * method; sf_cls_result counts the candidates identified after a given time (the window).
 *
 * Neighbourhood of port q (§III-C): q itself and every port linked to it; for each of them the
 * contexts of its building on its floors floor_lo..floor_hi, context_of(building, floor), and the
 * outdoor context(s) when it leads outdoors (port_outdoor = 1) or belongs to no building.
 * context_of(b, f) = the floor context of (b, f), else b's building context, else the outdoor
 * context (the paper: by default every relation is associated with the outdoor context); −1 when the
 * map has none of these. Building outlines: even-odd point-in-polygon test.
 *
 * Cost: a Wi-Fi or BLE reading O(n_cdd · n) (n APs or beacons heard; a few thousand comparisons for
 * a campus), a GNSS fix O(n_contexts), a result O(n_contexts), a neighbourhood O(n_links + floors ·
 * n_contexts), the outline test O(n_outline). Memory: sizeof(sf_cls_t) = 1 048 B on x86-64 (at most
 * 1 056 B, checked). No heap, no I/O, no clock. */
#ifndef SF_CLS_H
#define SF_CLS_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_radiomap.h"
#include "sf_types.h"

/* Most contexts one site may have: one bit each in the candidate mask. */
#define SF_CONTROLLER_MAX_CONTEXTS 64

/* The latest identification of one context. */
typedef struct {
    int64_t t_us; /* INT64_MIN: none since the search began */
    int16_t hits; /* constellation members heard within range (GNSS: 1) */
    int8_t method; /* sf_fix_wifi, sf_fix_ble or sf_fix_gnss */
} sf_cls_evidence_t;

typedef struct {
    bool searching;
    uint64_t candidates; /* bit i: context i is searched */
    sf_cls_evidence_t evidence[SF_CONTROLLER_MAX_CONTEXTS];
    uint32_t readings, identifications; /* counters, never decrease */
} sf_cls_t;
_Static_assert(sizeof(sf_cls_t) <= 1056, "sf_cls.h promises at most 1 056 B");

/* What the search found: the one candidate identified (−1 unless exactly one), how many candidates
 * there are and how many were identified, and the evidence of the unique one (method 0, hits 0: none). */
typedef struct {
    int16_t unique;
    int16_t candidates;
    int16_t identified;
    int8_t method;
    int16_t hits;
} sf_cls_result_t;

/* Starts a search over `candidates` (all earlier evidence forgotten); stops searching. */
void sf_cls_start(sf_cls_t *cls, uint64_t candidates);
void sf_cls_stop(sf_cls_t *cls);

/* One reading while searching (nothing otherwise). */
void sf_cls_wifi(sf_cls_t *cls, const sf_context_map_t *map, const sf_wifi_scan_t *scan);
void sf_cls_ble(sf_cls_t *cls, const sf_context_map_t *map, const sf_ble_scan_t *scan);
/* The floor a BLE scan identifies by the site's constellations, outside any search: the floor of the
 * one floor context with cdd_method BLE that the scan identifies (cdd_min_hits members at their
 * cdd_min_dbm or louder). SF_OK and *floor, or SF_ERANGE when no floor context is identified or
 * contexts of two floors are (a scan heard across a slab says nothing). The start-floor vote's BLE
 * evidence when the site has BLE constellations (sf_estimator_fix.c): the site builder measured them
 * on its survey, where the path-loss range only assumes what a slab costs. Cost O(n_cdd · n). */
int sf_cls_ble_floor(const sf_context_map_t *map, const sf_ble_scan_t *scan, int16_t *floor);
void sf_cls_gnss(sf_cls_t *cls, const sf_context_map_t *map, int64_t t_us, double accuracy_m,
                 double max_accuracy_m);

/* The candidates identified at or after since_us. */
void sf_cls_result(const sf_cls_t *cls, int64_t since_us, sf_cls_result_t *result);

/* Context i is a candidate of the search; ... and was identified at since_us or later. */
bool sf_cls_searches(const sf_cls_t *cls, int32_t context);
bool sf_cls_identified(const sf_cls_t *cls, int32_t context, int64_t since_us);

/* Masks: every context; a port's neighbourhood (*leads_outdoor: a port of it leads outdoors). */
uint64_t sf_cls_all(const sf_context_map_t *map);
uint64_t sf_cls_neighbourhood(const sf_site_t *site, int32_t port, bool *leads_outdoor);

/* Whether a candidate's CDD uses this method (sf_fix_*). */
bool sf_cls_uses(const sf_context_map_t *map, uint64_t candidates, int method);

/* context_of(building, floor) of the header (building −1: the outdoor context); −1: none. */
int16_t sf_cls_context_of(const sf_context_map_t *map, int32_t building, int32_t floor);

/* The context map's invariants (sf_context_check.c): at most SF_CONTROLLER_MAX_CONTEXTS contexts,
 * kinds, buildings (−1 exactly for outdoor), floors in the site's table, schemes < sf_scheme_count,
 * methods, CDD methods (Wi-Fi, BLE, GNSS), min hits ≥ 1, members' contexts in range and
 * non-decreasing, outlines of ≥ 3 consecutive vertices per building, port extras (building, outdoor
 * 0/1, steps > 0 exactly for stairs, finite endpoints), links in range. n_contexts = 0 passes (no
 * controller). SF_OK or SF_ERANGE; *what (may be NULL): a static text naming the first violation.
 * Cost O(n_contexts + n_cdd + n_outline · n_buildings + n_ports + n_links). */
int sf_cls_check_map(const sf_site_t *site, const char **what);

/* The building whose outline holds (x_m, y_m), or −1 (outside all). */
int32_t sf_cls_building_at(const sf_context_map_t *map, double x_m, double y_m);

#endif
