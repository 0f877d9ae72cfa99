/* sf_context_check.c — the context map's structural invariants (sf_cls.h, sf_cls_check_map), split
 * from sf_controller.c by concern: what a valid map is, apart from what the controller does with it. */
#include <math.h>
#include <stddef.h>

#include "sf_cls.h"
#include "sf_error.h"

static int fail(const char **const what, const char *const text)
{
    if (what != NULL) {
        *what = text;
    }
    return SF_ERANGE;
}

static bool floor_ok(const sf_site_t *const s, const int32_t floor)
{
    return s->n_floors <= 0 || (floor >= s->lowest_floor && floor < (int32_t)s->lowest_floor + s->n_floors);
}

static int check_contexts(const sf_site_t *const s, const char **const what)
{
    const sf_context_map_t *const m = &s->contexts;
    if (m->kind == NULL || m->building == NULL || m->floor == NULL || m->scheme == NULL || m->method == NULL ||
        m->cdd_method == NULL || m->cdd_min_hits == NULL) {
        return fail(what, "contexts: an array is missing");
    }
    for (int32_t i = 0; i < m->n_contexts; i++) {
        const int k = m->kind[i];
        if (k != sf_context_outdoor && k != sf_context_building && k != sf_context_floor) {
            return fail(what, "context_kind is not a CONTEXT_* constant");
        }
        if ((k == sf_context_outdoor) != (m->building[i] < 0) || m->building[i] >= m->n_buildings ||
            m->building[i] < -1) {
            return fail(what, "context_building out of range (-1 exactly for the outdoor context)");
        }
        if (!floor_ok(s, m->floor[i])) {
            return fail(what, "context_floor outside the site's floors");
        }
        if (m->scheme[i] < 0 || m->scheme[i] >= sf_scheme_count) {
            return fail(what, "context_scheme is not a fusion scheme");
        }
        if (m->method[i] < sf_fix_wifi || m->method[i] > sf_fix_ble) {
            return fail(what, "context_method is not an absolute method");
        }
        const int cm = m->cdd_method[i];
        if (cm != sf_fix_wifi && cm != sf_fix_ble && cm != sf_fix_gnss) {
            return fail(what, "context_cdd_method is not Wi-Fi, BLE or GNSS");
        }
        if (m->cdd_min_hits[i] < 1) {
            return fail(what, "context_cdd_min_hits below 1");
        }
    }
    if (m->n_cdd < 0 || (m->n_cdd > 0 && (m->cdd_context == NULL || m->cdd_id == NULL || m->cdd_min_dbm == NULL))) {
        return fail(what, "cdd: negative count or an array missing");
    }
    for (int32_t k = 0; k < m->n_cdd; k++) {
        if (m->cdd_context[k] < 0 || m->cdd_context[k] >= m->n_contexts ||
            (k > 0 && m->cdd_context[k] < m->cdd_context[k - 1])) {
            return fail(what, "cdd_context out of range or decreasing");
        }
        if (!isfinite(m->cdd_min_dbm[k])) {
            return fail(what, "cdd_min_dbm not finite");
        }
    }
    return SF_OK;
}

static int check_geometry(const sf_site_t *const s, const char **const what)
{
    const sf_context_map_t *const m = &s->contexts;
    if (m->n_buildings < 0 || m->n_outline < 0 ||
        (m->n_outline > 0 && (m->outline_x_m == NULL || m->outline_y_m == NULL || m->outline_building == NULL))) {
        return fail(what, "outlines: negative count or an array missing");
    }
    for (int32_t start = 0, i = 0; i <= m->n_outline; i++) {
        if (i < m->n_outline && (m->outline_building[i] < 0 || m->outline_building[i] >= m->n_buildings ||
                                 !isfinite(m->outline_x_m[i]) || !isfinite(m->outline_y_m[i]))) {
            return fail(what, "outline vertex: building out of range or not finite");
        }
        if (i == m->n_outline || (i > start && m->outline_building[i] != m->outline_building[start])) {
            if (i - start < 3 && i > start) {
                return fail(what, "outline: fewer than 3 consecutive vertices for a building");
            }
            for (int32_t j = 0; j < start && i < m->n_outline; j++) {
                if (m->outline_building[j] == m->outline_building[i]) {
                    return fail(what, "outline: a building's vertices are not consecutive");
                }
            }
            start = i;
        }
    }
    const int32_t np = s->ports.n_ports;
    if (np > 0 && (m->port_building == NULL || m->port_outdoor == NULL || m->port_steps == NULL ||
                   m->port_lo_x_m == NULL || m->port_lo_y_m == NULL || m->port_hi_x_m == NULL ||
                   m->port_hi_y_m == NULL)) {
        return fail(what, "port extras: an array is missing");
    }
    for (int32_t q = 0; q < np; q++) {
        if (m->port_building[q] < -1 || m->port_building[q] >= m->n_buildings) {
            return fail(what, "port_building out of range");
        }
        if (m->port_outdoor[q] != 0 && m->port_outdoor[q] != 1) {
            return fail(what, "port_outdoor is not 0 or 1");
        }
        if (m->port_steps[q] < 0 || (s->ports.kind[q] == sf_port_stairs) != (m->port_steps[q] > 0)) {
            return fail(what, "port_steps: > 0 exactly for stairs");
        }
        if (!(isfinite(m->port_lo_x_m[q]) && isfinite(m->port_lo_y_m[q]) && isfinite(m->port_hi_x_m[q]) &&
              isfinite(m->port_hi_y_m[q]))) {
            return fail(what, "port endpoint not finite");
        }
    }
    if (m->n_links < 0 || (m->n_links > 0 && (m->link_a == NULL || m->link_b == NULL))) {
        return fail(what, "links: negative count or an array missing");
    }
    for (int32_t k = 0; k < m->n_links; k++) {
        if (m->link_a[k] < 0 || m->link_a[k] >= np || m->link_b[k] < 0 || m->link_b[k] >= np) {
            return fail(what, "link port out of range");
        }
    }
    return SF_OK;
}

int sf_cls_check_map(const sf_site_t *const site, const char **const what)
{
    if (what != NULL) {
        *what = "ok";
    }
    const int32_t n = site->contexts.n_contexts;
    if (n < 0 || n > SF_CONTROLLER_MAX_CONTEXTS) {
        return fail(what, "n_contexts negative or above SF_CONTROLLER_MAX_CONTEXTS");
    }
    if (n == 0) {
        return SF_OK;
    }
    const int rc = check_contexts(site, what);
    return rc == SF_OK ? check_geometry(site, what) : rc;
}
