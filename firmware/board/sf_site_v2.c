/* sf_site_v2.c — version-2 site content: walk, rules and view (see sf_site_v2.h). */
#include "sf_site_v2.h"

#include <math.h>

#include "sf_error.h"

int sf_site_v2_walk(sf_lcm_walk_t *const w, int32_t *const n_ports)
{
    int rc = sf_lcm_walk_skip(w, 8 + 8, "origin_alt_m, geo_rotation_deg");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_walls", 4 * 4 + 2);
    const size_t ports_at = w->pos;
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_ports", 2 + 3 * 4 + 2 * 2);
    *n_ports = rc == SF_OK ? sf_lcm_be32(w->p + ports_at) : 0; /* checked ≥ 0 by the walk */
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_beacons", 8 + 4 + 4 + 2 + 4);
    return rc != SF_OK ? rc : sf_lcm_walk_skip(w, 3 * 4, "ble_rssi_1m_dbm .. ble_range_sigma_db");
}

#define BAD(...) sf_lcm_failf(err, err_size, name, SF_ERANGE, __VA_ARGS__)

int sf_site_v2_check_geo(const stridefix_site_t *const s, const char *const name, char *const err,
                         const size_t err_size)
{
    if (!isfinite(s->origin_alt_m)) {
        return BAD("origin_alt_m is %g, must be finite", s->origin_alt_m);
    }
    if (!isfinite(s->geo_rotation_deg)) {
        return BAD("geo_rotation_deg is %g, must be finite", s->geo_rotation_deg);
    }
    return SF_OK;
}

static int check_walls(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                       char *const err, const size_t err_size)
{
    for (int32_t i = 0; i < s->n_walls; i++) {
        const float x0 = s->wall_x0_m[i], y0 = s->wall_y0_m[i], x1 = s->wall_x1_m[i], y1 = s->wall_y1_m[i];
        const int f = s->wall_floor[i];
        if (!(isfinite(x0) && isfinite(y0) && isfinite(x1) && isfinite(y1))) {
            return BAD("wall %d: end points (%g, %g) - (%g, %g) not finite", (int)i, (double)x0, (double)y0,
                       (double)x1, (double)y1);
        }
        if (f < lowest || f > top) {
            return BAD("wall %d: floor %d outside %d..%d", (int)i, f, lowest, top);
        }
        if (x0 == x1 && y0 == y1) {
            return BAD("wall %d: zero length at (%g, %g)", (int)i, (double)x0, (double)y0);
        }
    }
    return SF_OK;
}

static int check_ports(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                       char *const err, const size_t err_size)
{
    for (int32_t i = 0; i < s->n_ports; i++) {
        const int kind = s->port_kind[i];
        const float x = s->port_x_m[i], y = s->port_y_m[i], r = s->port_radius_m[i];
        const int lo = s->port_floor_lo[i], hi = s->port_floor_hi[i];
        if (kind != sf_port_door && kind != sf_port_stairs && kind != sf_port_elevator) {
            return BAD("port %d: kind %d unknown (1 door, 2 stairs, 3 elevator)", (int)i, kind);
        }
        if (!(isfinite(x) && isfinite(y))) {
            return BAD("port %d: position (%g, %g) not finite", (int)i, (double)x, (double)y);
        }
        if (!(isfinite(r) && r > 0.0f)) {
            return BAD("port %d: port_radius_m = %g, must be finite and > 0", (int)i, (double)r);
        }
        if (lo > hi) {
            return BAD("port %d: floor_lo %d above floor_hi %d", (int)i, lo, hi);
        }
        if (lo < lowest || hi > top) {
            return BAD("port %d: floors %d..%d outside %d..%d", (int)i, lo, hi, lowest, top);
        }
    }
    return SF_OK;
}

static int check_beacons(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                         char *const err, const size_t err_size)
{
    for (int32_t i = 0; i < s->n_beacons; i++) {
        const int64_t b = s->beacon_id[i];
        const float x = s->beacon_x_m[i], y = s->beacon_y_m[i];
        const int f = s->beacon_floor[i];
        if (b < 0 || b >= ((int64_t)1 << 48)) {
            return BAD("beacon %d: id %lld outside 0..2^48-1", (int)i, (long long)b);
        }
        if (i > 0 && !(b > s->beacon_id[i - 1])) {
            return BAD("beacon %d: id 0x%012llx not above beacon %d's 0x%012llx (ids must be strictly ascending)",
                       (int)i, (unsigned long long)b, (int)(i - 1), (unsigned long long)s->beacon_id[i - 1]);
        }
        if (!(isfinite(x) && isfinite(y))) {
            return BAD("beacon %d: position (%g, %g) not finite", (int)i, (double)x, (double)y);
        }
        if (f < lowest || f > top) {
            return BAD("beacon %d: floor %d outside %d..%d", (int)i, f, lowest, top);
        }
        if (isinf(s->beacon_rssi_1m_dbm[i])) {
            return BAD("beacon %d: beacon_rssi_1m_dbm is %g, must be finite or NaN (unknown)", (int)i,
                       (double)s->beacon_rssi_1m_dbm[i]);
        }
    }
    if (s->n_beacons > 0) {
        if (!isfinite(s->ble_rssi_1m_dbm)) {
            return BAD("ble_rssi_1m_dbm is %g, must be finite", (double)s->ble_rssi_1m_dbm);
        }
        if (!(isfinite(s->ble_path_loss_exponent) && s->ble_path_loss_exponent > 0.0f)) {
            return BAD("ble_path_loss_exponent = %g, must be finite and > 0", (double)s->ble_path_loss_exponent);
        }
        if (!(isfinite(s->ble_range_sigma_db) && s->ble_range_sigma_db > 0.0f)) {
            return BAD("ble_range_sigma_db = %g, must be finite and > 0", (double)s->ble_range_sigma_db);
        }
    }
    return SF_OK;
}

int sf_site_v2_check_plan(const stridefix_site_t *const s, const int lowest, const int top, const char *const name,
                          char *const err, const size_t err_size)
{
    int rc = check_walls(s, lowest, top, name, err, err_size);
    rc = rc != SF_OK ? rc : check_ports(s, lowest, top, name, err, err_size);
    return rc != SF_OK ? rc : check_beacons(s, lowest, top, name, err, err_size);
}

#undef BAD

void sf_site_v2_view(const stridefix_site_t *const s, sf_site_t *const site)
{
    site->geo = (sf_geo_ref_t){.valid = s->has_geo,
                               .origin_lat_deg = s->origin_lat_deg,
                               .origin_lon_deg = s->origin_lon_deg,
                               .origin_alt_m = s->origin_alt_m,
                               .rotation_deg = s->geo_rotation_deg};
    site->plan = (sf_floor_plan_t){.n_walls = s->n_walls,
                                   .x0_m = s->wall_x0_m,
                                   .y0_m = s->wall_y0_m,
                                   .x1_m = s->wall_x1_m,
                                   .y1_m = s->wall_y1_m,
                                   .floor = s->wall_floor};
    site->ports = (sf_ports_t){.n_ports = s->n_ports,
                               .kind = s->port_kind,
                               .x_m = s->port_x_m,
                               .y_m = s->port_y_m,
                               .radius_m = s->port_radius_m,
                               .floor_lo = s->port_floor_lo,
                               .floor_hi = s->port_floor_hi};
    site->beacons = (sf_beacons_t){.n_beacons = s->n_beacons,
                                   .id = s->beacon_id,
                                   .x_m = s->beacon_x_m,
                                   .y_m = s->beacon_y_m,
                                   .floor = s->beacon_floor,
                                   .rssi_1m_dbm = s->beacon_rssi_1m_dbm,
                                   .site_rssi_1m_dbm = s->ble_rssi_1m_dbm,
                                   .path_loss_exponent = s->ble_path_loss_exponent,
                                   .range_sigma_db = s->ble_range_sigma_db};
}
