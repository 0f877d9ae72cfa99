/* sf_site_v2.h — the site file's version-2 content (geo-reference, walls, ports, BLE beacons): its
 * payload walk, field rules and core view, for sf_site.c (not a public API).
 *
 * The rules, their order and their words are analyzer/stridefix_analyzer/io/site_v2.py's: geo (when
 * has_geo) altitude and rotation finite; walls with finite end points, a floor within the site's and
 * non-zero length; ports of a known kind, finite centre, radius > 0, floor_lo ≤ floor_hi within the
 * site's floors; beacons with ids 0 … 2^48−1 strictly ascending, finite position, floor within the
 * site's, own RSSI at 1 m finite or NaN; with beacons, the site's path-loss model finite with
 * exponent > 0 and sigma > 0. Cost O(n_walls + n_ports + n_beacons), no allocation. */
#ifndef SF_SITE_V2_H
#define SF_SITE_V2_H

#include <stddef.h>
#include <stdint.h>

#include "sf_lcm_walk.h"
#include "sf_radiomap.h"
#include "stridefix_site_t.h"

/* Walks origin_alt_m .. ble_range_sigma_db (the fields after fix_white_share); *n_ports gets the
 * port count read (the version-3 per-port extras are sized by it). */
int sf_site_v2_walk(sf_lcm_walk_t *w, int32_t *n_ports);

/* The geo rules (call when has_geo); SF_OK or SF_ERANGE with "<name>: <what>" in err. */
int sf_site_v2_check_geo(const stridefix_site_t *s, const char *name, char *err, size_t err_size);

/* The wall, port and beacon rules against floors lowest .. top. */
int sf_site_v2_check_plan(const stridefix_site_t *s, int lowest, int top, const char *name, char *err,
                          size_t err_size);

/* Fills site->geo, plan, ports and beacons from the checked s (pointers into s's arrays). */
void sf_site_v2_view(const stridefix_site_t *s, sf_site_t *site);

#endif
