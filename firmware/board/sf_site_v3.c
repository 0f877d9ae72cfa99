/* sf_site_v3.c — version-3 site content: walk, rules and view (see sf_site_v3.h). */
#include "sf_site_v3.h"

#include <math.h>
#include <stdlib.h>

#include "sf_error.h"
#include "sf_types.h"

int sf_site_v3_walk(sf_lcm_walk_t *const w, const int32_t n_ports)
{
    /* n_buildings, then that many strings (each ≥ 4 + 1 bytes, so the count is bounded first) */
    int rc = sf_lcm_walk_skip(w, 4, "n_buildings");
    if (rc != SF_OK) {
        return rc;
    }
    const int32_t n_buildings = sf_lcm_be32(w->p + w->pos - 4);
    if (n_buildings < 0) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX, "payload: n_buildings = %d is negative",
                            (int)n_buildings);
    }
    if ((size_t)n_buildings > (w->size - w->pos) / 5u) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX,
                            "payload: n_buildings = %d needs %zu bytes of names at least, %zu left", (int)n_buildings,
                            (size_t)n_buildings * 5u, w->size - w->pos);
    }
    for (int32_t i = 0; i < n_buildings && rc == SF_OK; i++) {
        rc = sf_lcm_walk_string(w, "building_name");
    }
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_outline", 4 + 4 + 2);
    /* the per-port extras: 3 int16 and 4 float per port of the version-2 count */
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(w, (size_t)n_ports * (3u * 2u + 4u * 4u), "port_building .. port_hi_y_m");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_links", 4 + 4);
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_contexts", 7 * 2);
    return rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_cdd", 2 + 8 + 4);
}

#define BAD(...) sf_lcm_failf(err, err_size, name, SF_ERANGE, __VA_ARGS__)

static int check_outlines(const stridefix_site_t *const s, const char *const name, char *const err,
                          const size_t err_size)
{
    const int32_t nb = s->n_buildings;
    if (nb == 0 && s->n_outline == 0) {
        return SF_OK;
    }
    /* first[b]: building b's first vertex (−1: none yet); count[b]: its vertices */
    int32_t *const first = malloc(sizeof(int32_t) * 2u * ((size_t)nb + 1u));
    if (first == NULL) {
        return sf_lcm_failf(err, err_size, name, SF_EIO, "out of memory for the outline check (%d buildings)",
                            (int)nb);
    }
    int32_t *const count = first + nb + 1;
    for (int32_t b = 0; b <= nb; b++) {
        first[b] = -1;
        count[b] = 0;
    }
    int rc = SF_OK;
    for (int32_t i = 0; i < s->n_outline && rc == SF_OK; i++) {
        const int b = s->outline_building[i];
        const float x = s->outline_x_m[i], y = s->outline_y_m[i];
        const int prev = i > 0 ? s->outline_building[i - 1] : -1;
        if (b < 0 || b >= nb) {
            rc = BAD("outline vertex %d: building %d outside 0..%d", (int)i, b, (int)(nb - 1));
        } else if (!(isfinite(x) && isfinite(y))) {
            rc = BAD("outline vertex %d: position (%g, %g) not finite", (int)i, (double)x, (double)y);
        } else if (b != prev && first[b] >= 0) {
            rc = BAD("outline vertex %d: building %d's vertices not consecutive (its first is vertex %d)", (int)i, b,
                     (int)first[b]);
        } else {
            if (first[b] < 0) {
                first[b] = i;
            }
            count[b]++;
        }
    }
    for (int32_t b = 0; b < nb && rc == SF_OK; b++) {
        if (count[b] < 3) {
            rc = BAD("building %d: %d outline vertices, needs at least 3", (int)b, (int)count[b]);
        }
    }
    free(first);
    return rc;
}

static int check_port_extras(const stridefix_site_t *const s, const char *const name, char *const err,
                             const size_t err_size)
{
    for (int32_t i = 0; i < s->n_ports; i++) {
        const int b = s->port_building[i], out = s->port_outdoor[i], steps = s->port_steps[i];
        if (b < -1 || b >= s->n_buildings) {
            return BAD("port %d: port_building %d outside -1..%d", (int)i, b, (int)(s->n_buildings - 1));
        }
        if (out != 0 && out != 1) {
            return BAD("port %d: port_outdoor %d is not 0 or 1", (int)i, out);
        }
        if (steps < 0) {
            return BAD("port %d: port_steps %d is negative", (int)i, steps);
        }
        if (steps == 0 && s->port_kind[i] == sf_port_stairs && s->n_contexts > 0) {
            return BAD("port %d: stairs with port_steps 0 (a staircase needs its step count when the site has "
                       "contexts)",
                       (int)i);
        }
        if (steps != 0 && s->port_kind[i] != sf_port_stairs) {
            return BAD("port %d: a %s with port_steps %d (steps are a staircase's: 0 for doors and elevators)",
                       (int)i, s->port_kind[i] == sf_port_door ? "door" : "elevator", steps);
        }
        const float lx = s->port_lo_x_m[i], ly = s->port_lo_y_m[i], hx = s->port_hi_x_m[i], hy = s->port_hi_y_m[i];
        if (!(isfinite(lx) && isfinite(ly) && isfinite(hx) && isfinite(hy))) {
            return BAD("port %d: endpoints (%g, %g) - (%g, %g) not finite", (int)i, (double)lx, (double)ly,
                       (double)hx, (double)hy);
        }
    }
    return SF_OK;
}

static int check_links(const stridefix_site_t *const s, const char *const name, char *const err,
                       const size_t err_size)
{
    for (int32_t i = 0; i < s->n_links; i++) {
        const int32_t ends[2] = {s->link_a[i], s->link_b[i]};
        for (int k = 0; k < 2; k++) {
            if (ends[k] < 0 || ends[k] >= s->n_ports) {
                return BAD("link %d: port %d outside 0..%d", (int)i, (int)ends[k], (int)(s->n_ports - 1));
            }
        }
        if (ends[0] == ends[1]) {
            return BAD("link %d: links port %d with itself", (int)i, (int)ends[0]);
        }
    }
    return SF_OK;
}

static int is_context_method(const int m)
{
    return m == sf_fix_wifi || m == sf_fix_gnss || m == sf_fix_ble;
}

static int check_contexts(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                          char *const err, const size_t err_size)
{
    int outdoor = -1;
    for (int32_t i = 0; i < s->n_contexts; i++) {
        const int kind = s->context_kind[i], b = s->context_building[i], f = s->context_floor[i];
        const int scheme = s->context_scheme[i], method = s->context_method[i];
        const int cdd_method = s->context_cdd_method[i], hits = s->context_cdd_min_hits[i];
        if (kind != sf_context_outdoor && kind != sf_context_building && kind != sf_context_floor) {
            return BAD("context %d: kind %d unknown (1 outdoor, 2 building, 3 floor)", (int)i, kind);
        }
        if (kind == sf_context_outdoor && b != -1) {
            return BAD("context %d: an outdoor context has building %d, must be -1", (int)i, b);
        }
        if (kind != sf_context_outdoor && (b < 0 || b >= s->n_buildings)) {
            return BAD("context %d: building %d outside 0..%d", (int)i, b, (int)(s->n_buildings - 1));
        }
        if (f < lowest || f > top) {
            return BAD("context %d: floor %d outside %d..%d", (int)i, f, lowest, top);
        }
        if (scheme < 0 || scheme >= (int)sf_scheme_count) {
            return BAD("context %d: scheme %d is not a fusion scheme (0..%d)", (int)i, scheme,
                       (int)sf_scheme_count - 1);
        }
        if (!is_context_method(method)) {
            return BAD("context %d: method %d is not wifi (1), gnss (2) or ble (4)", (int)i, method);
        }
        if (!is_context_method(cdd_method)) {
            return BAD("context %d: cdd_method %d is not wifi (1), gnss (2) or ble (4)", (int)i, cdd_method);
        }
        if (hits < 1) {
            return BAD("context %d: cdd_min_hits %d, must be >= 1", (int)i, hits);
        }
        if (kind == sf_context_outdoor) {
            if (outdoor >= 0) {
                return BAD("context %d: a second outdoor context (context %d is one)", (int)i, outdoor);
            }
            outdoor = (int)i;
        }
        for (int32_t j = 0; j < i; j++) {
            if (s->context_kind[j] == kind && s->context_building[j] == b && s->context_floor[j] == f) {
                return BAD("context %d: kind %d, building %d, floor %d already context %d", (int)i, kind, b, f,
                           (int)j);
            }
        }
    }
    return SF_OK;
}

static int check_cdd(const stridefix_site_t *const s, const char *const name, char *const err, const size_t err_size)
{
    for (int32_t i = 0; i < s->n_cdd; i++) {
        const int c = s->cdd_context[i];
        const int64_t id = s->cdd_id[i];
        const float dbm = s->cdd_min_dbm[i];
        if (c < 0 || c >= s->n_contexts) {
            return BAD("cdd %d: context %d outside 0..%d", (int)i, c, (int)(s->n_contexts - 1));
        }
        if (i > 0 && c < s->cdd_context[i - 1]) {
            return BAD("cdd %d: context %d below cdd %d's %d (must be non-decreasing)", (int)i, c, (int)(i - 1),
                       (int)s->cdd_context[i - 1]);
        }
        if (id < 0 || id >= ((int64_t)1 << 48)) {
            return BAD("cdd %d: id %lld outside 0..2^48-1", (int)i, (long long)id);
        }
        if (!isfinite(dbm)) {
            return BAD("cdd %d: cdd_min_dbm is %g, must be finite", (int)i, (double)dbm);
        }
        if (s->context_cdd_method[c] == sf_fix_gnss) {
            return BAD("cdd %d: context %d is recognised by GNSS and has no constellation", (int)i, c);
        }
    }
    return SF_OK;
}

int sf_site_v3_check(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                     char *const err, const size_t err_size)
{
    int rc = check_outlines(s, name, err, err_size);
    rc = rc != SF_OK ? rc : check_port_extras(s, name, err, err_size);
    rc = rc != SF_OK ? rc : check_links(s, name, err, err_size);
    rc = rc != SF_OK ? rc : check_contexts(s, lowest, top, name, err, err_size);
    return rc != SF_OK ? rc : check_cdd(s, name, err, err_size);
}

#undef BAD

void sf_site_v3_view(const stridefix_site_t *const s, sf_site_t *const site)
{
    site->contexts = (sf_context_map_t){.n_buildings = s->n_buildings,
                                        .n_outline = s->n_outline,
                                        .outline_x_m = s->outline_x_m,
                                        .outline_y_m = s->outline_y_m,
                                        .outline_building = s->outline_building,
                                        .port_building = s->port_building,
                                        .port_outdoor = s->port_outdoor,
                                        .port_steps = s->port_steps,
                                        .port_lo_x_m = s->port_lo_x_m,
                                        .port_lo_y_m = s->port_lo_y_m,
                                        .port_hi_x_m = s->port_hi_x_m,
                                        .port_hi_y_m = s->port_hi_y_m,
                                        .n_links = s->n_links,
                                        .link_a = s->link_a,
                                        .link_b = s->link_b,
                                        .n_contexts = s->n_contexts,
                                        .kind = s->context_kind,
                                        .building = s->context_building,
                                        .floor = s->context_floor,
                                        .scheme = s->context_scheme,
                                        .method = s->context_method,
                                        .cdd_method = s->context_cdd_method,
                                        .cdd_min_hits = s->context_cdd_min_hits,
                                        .n_cdd = s->n_cdd,
                                        .cdd_context = s->cdd_context,
                                        .cdd_id = s->cdd_id,
                                        .cdd_min_dbm = s->cdd_min_dbm};
}
