/* sf_cls.c — the coarse localization subsystem and the context map's geometry (see sf_cls.h). */
#include "sf_cls.h"

#include <stddef.h>

#include "sf_error.h"

static uint64_t bit(const int32_t i)
{
    return (uint64_t)1 << (uint32_t)i;
}

static int32_t n_contexts(const sf_context_map_t *const map)
{
    return map->n_contexts < SF_CONTROLLER_MAX_CONTEXTS ? map->n_contexts : SF_CONTROLLER_MAX_CONTEXTS;
}

void sf_cls_start(sf_cls_t *const cls, const uint64_t candidates)
{
    cls->searching = true;
    cls->candidates = candidates;
    for (int32_t i = 0; i < SF_CONTROLLER_MAX_CONTEXTS; i++) {
        cls->evidence[i] = (sf_cls_evidence_t){.t_us = INT64_MIN};
    }
}

void sf_cls_stop(sf_cls_t *const cls)
{
    cls->searching = false;
}

static void identify(sf_cls_t *const cls, const int32_t context, const int64_t t_us, const int16_t hits,
                     const int8_t method)
{
    cls->evidence[context] = (sf_cls_evidence_t){.t_us = t_us, .hits = hits, .method = method};
    cls->identifications++;
}

/* Members heard at their threshold per context of this CDD method among the candidates (each
 * member counted once). */
static void count_hits(const sf_context_map_t *const map, const uint64_t candidates, const int8_t method,
                       const int32_t n, const int64_t *const id, const float *const rssi_dbm,
                       int16_t hits[SF_CONTROLLER_MAX_CONTEXTS])
{
    for (int32_t k = 0; k < map->n_cdd; k++) {
        const int32_t ctx = map->cdd_context[k];
        if (ctx >= n_contexts(map) || (candidates & bit(ctx)) == 0 || map->cdd_method[ctx] != method) {
            continue;
        }
        for (int32_t j = 0; j < n; j++) {
            if (id[j] == map->cdd_id[k] && rssi_dbm[j] >= map->cdd_min_dbm[k]) {
                hits[ctx]++;
                break; /* a member counts once */
            }
        }
    }
}

/* Members heard per candidate context of this CDD method, then the identifications. */
static void constellations(sf_cls_t *const cls, const sf_context_map_t *const map, const int8_t method,
                           const int64_t t_us, const int32_t n, const int64_t *const id, const float *const rssi_dbm)
{
    if (!cls->searching) {
        return;
    }
    cls->readings++;
    int16_t hits[SF_CONTROLLER_MAX_CONTEXTS] = {0};
    count_hits(map, cls->candidates, method, n, id, rssi_dbm, hits);
    for (int32_t i = 0; i < n_contexts(map); i++) {
        if (hits[i] > 0 && hits[i] >= map->cdd_min_hits[i]) {
            identify(cls, i, t_us, hits[i], method);
        }
    }
}

void sf_cls_wifi(sf_cls_t *const cls, const sf_context_map_t *const map, const sf_wifi_scan_t *const scan)
{
    constellations(cls, map, sf_fix_wifi, scan->t_us, scan->n_ap, scan->bssid, scan->rssi_dbm);
}

void sf_cls_ble(sf_cls_t *const cls, const sf_context_map_t *const map, const sf_ble_scan_t *const scan)
{
    constellations(cls, map, sf_fix_ble, scan->t_us, scan->n, scan->beacon_id, scan->rssi_dbm);
}

int sf_cls_ble_floor(const sf_context_map_t *const map, const sf_ble_scan_t *const scan, int16_t *const floor)
{
    int16_t hits[SF_CONTROLLER_MAX_CONTEXTS] = {0};
    count_hits(map, sf_cls_all(map), sf_fix_ble, scan->n, scan->beacon_id, scan->rssi_dbm, hits);
    bool found = false;
    for (int32_t i = 0; i < n_contexts(map); i++) {
        if (map->kind[i] != sf_context_floor || hits[i] == 0 || hits[i] < map->cdd_min_hits[i]) {
            continue;
        }
        if (found && map->floor[i] != *floor) {
            return SF_ERANGE; /* two floors heard at once */
        }
        *floor = map->floor[i];
        found = true;
    }
    return found ? SF_OK : SF_ERANGE;
}

void sf_cls_gnss(sf_cls_t *const cls, const sf_context_map_t *const map, const int64_t t_us,
                 const double accuracy_m, const double max_accuracy_m)
{
    if (!cls->searching) {
        return;
    }
    cls->readings++;
    if (!(accuracy_m >= 0.0 && accuracy_m <= max_accuracy_m)) { /* NaN too */
        return;
    }
    for (int32_t i = 0; i < n_contexts(map); i++) {
        if (sf_cls_searches(cls, i) && map->cdd_method[i] == sf_fix_gnss) {
            identify(cls, i, t_us, 1, sf_fix_gnss);
        }
    }
}

bool sf_cls_searches(const sf_cls_t *const cls, const int32_t context)
{
    return context >= 0 && context < SF_CONTROLLER_MAX_CONTEXTS && (cls->candidates & bit(context)) != 0;
}

bool sf_cls_identified(const sf_cls_t *const cls, const int32_t context, const int64_t since_us)
{
    return sf_cls_searches(cls, context) && cls->evidence[context].t_us != INT64_MIN &&
           cls->evidence[context].t_us >= since_us;
}

void sf_cls_result(const sf_cls_t *const cls, const int64_t since_us, sf_cls_result_t *const r)
{
    *r = (sf_cls_result_t){.unique = -1};
    int32_t last = -1;
    for (int32_t i = 0; i < SF_CONTROLLER_MAX_CONTEXTS; i++) {
        if (!sf_cls_searches(cls, i)) {
            continue;
        }
        r->candidates++;
        if (sf_cls_identified(cls, i, since_us)) {
            r->identified++;
            last = i;
        }
    }
    if (r->identified == 1) {
        r->unique = (int16_t)last;
        r->method = cls->evidence[last].method;
        r->hits = cls->evidence[last].hits;
    }
}

uint64_t sf_cls_all(const sf_context_map_t *const map)
{
    const int32_t n = n_contexts(map);
    return n >= 64 ? UINT64_MAX : bit(n) - 1u;
}

int16_t sf_cls_context_of(const sf_context_map_t *const map, const int32_t building, const int32_t floor)
{
    int16_t of_building = -1, outdoor = -1;
    for (int32_t i = 0; i < n_contexts(map); i++) {
        if (map->kind[i] == sf_context_outdoor) {
            outdoor = outdoor < 0 ? (int16_t)i : outdoor;
        } else if (building >= 0 && map->building[i] == building) {
            if (map->kind[i] == sf_context_floor && map->floor[i] == floor) {
                return (int16_t)i;
            }
            if (map->kind[i] == sf_context_building && of_building < 0) {
                of_building = (int16_t)i;
            }
        }
    }
    return of_building >= 0 ? of_building : outdoor;
}

static uint64_t outdoors(const sf_context_map_t *const map)
{
    uint64_t m = 0;
    for (int32_t i = 0; i < n_contexts(map); i++) {
        m |= map->kind[i] == sf_context_outdoor ? bit(i) : 0u;
    }
    return m;
}

/* One port's share of a neighbourhood. */
static uint64_t port_contexts(const sf_site_t *const site, const int32_t q, bool *const leads_outdoor)
{
    const sf_context_map_t *const map = &site->contexts;
    const int32_t b = map->port_building[q];
    uint64_t m = 0;
    for (int32_t f = site->ports.floor_lo[q]; f <= site->ports.floor_hi[q]; f++) {
        const int16_t c = sf_cls_context_of(map, b, f);
        m |= c >= 0 ? bit(c) : 0u;
    }
    if (map->port_outdoor[q] != 0 || b < 0) {
        m |= outdoors(map);
        *leads_outdoor = *leads_outdoor || map->port_outdoor[q] != 0;
    }
    return m;
}

uint64_t sf_cls_neighbourhood(const sf_site_t *const site, const int32_t port, bool *const leads_outdoor)
{
    *leads_outdoor = false;
    uint64_t m = port_contexts(site, port, leads_outdoor); /* a port is its own neighbour */
    const sf_context_map_t *const map = &site->contexts;
    for (int32_t k = 0; k < map->n_links; k++) {
        const int32_t other = map->link_a[k] == port ? map->link_b[k] : (map->link_b[k] == port ? map->link_a[k] : -1);
        if (other >= 0) {
            m |= port_contexts(site, other, leads_outdoor);
        }
    }
    return m;
}

bool sf_cls_uses(const sf_context_map_t *const map, const uint64_t candidates, const int method)
{
    for (int32_t i = 0; i < n_contexts(map); i++) {
        if ((candidates & bit(i)) != 0 && map->cdd_method[i] == method) {
            return true;
        }
    }
    return false;
}

int32_t sf_cls_building_at(const sf_context_map_t *const map, const double x_m, const double y_m)
{
    int32_t start = 0;
    while (start < map->n_outline) { /* one building's vertices [start, end) */
        const int16_t b = map->outline_building[start];
        int32_t end = start;
        while (end < map->n_outline && map->outline_building[end] == b) {
            end++;
        }
        bool inside = false;
        for (int32_t i = start, j = end - 1; i < end; j = i++) {
            const double xi = map->outline_x_m[i], yi = map->outline_y_m[i];
            const double xj = map->outline_x_m[j], yj = map->outline_y_m[j];
            if ((yi > y_m) != (yj > y_m) && x_m < (xj - xi) * (y_m - yi) / (yj - yi) + xi) {
                inside = !inside;
            }
        }
        if (inside) {
            return b;
        }
        start = end;
    }
    return -1;
}
