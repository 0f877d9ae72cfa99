/* sf_site_v3.h — the site file's version-3 content (the multi-scheme controller's positioning context
 * map: buildings and outlines, per-port extras, port links, contexts, constellations; Jäger, Süß,
 * Becker §III-C): its payload walk, field rules and core view (sf_context_map_t), for sf_site.c (not a
 * public API).
 *
 * The rules, their order and their words are analyzer/stridefix_analyzer/io/site_v3.py's: outline
 * vertices with a building in range, a finite position, each building's vertices consecutive, then
 * ≥ 3 per building; port extras with port_building −1 … n_buildings−1, port_outdoor 0/1, port_steps
 * ≥ 0 (> 0 for stairs when the site has contexts, 0 for doors and elevators), finite endpoints; links with both ports in range,
 * not a port with itself; contexts of a known kind, building −1 for the outdoor one and in range for
 * the others, a floor within the site's, a fusion scheme (< sf_scheme_count), method and cdd_method
 * one of sf_fix_wifi/gnss/ble, cdd_min_hits ≥ 1, one outdoor context at most, one context per
 * (kind, building, floor); constellation members with a context in range and non-decreasing, an id
 * 0 … 2^48−1, a finite cdd_min_dbm, none for a GNSS context.
 * Cost O(n_outline + n_buildings + n_ports + n_links + n_contexts² + n_cdd) (contexts are a handful);
 * the outline check allocates one table of 2·n_buildings int32 (each building's first vertex and
 * vertex count) and frees it before returning. */
#ifndef SF_SITE_V3_H
#define SF_SITE_V3_H

#include <stddef.h>
#include <stdint.h>

#include "sf_lcm_walk.h"
#include "sf_radiomap.h"
#include "stridefix_site_t.h"

/* Walks n_buildings .. cdd_min_dbm (the fields after ble_range_sigma_db); n_ports is the count the
 * version-2 walk read (the per-port extras are sized by it). */
int sf_site_v3_walk(sf_lcm_walk_t *w, int32_t n_ports);

/* The version-3 rules against floors lowest .. top; SF_OK or SF_ERANGE with "<name>: <what>"
 * (SF_EIO when the outline table cannot be allocated). */
int sf_site_v3_check(const stridefix_site_t *s, int lowest, int top, const char *name, char *err,
                     size_t err_size);

/* Fills site->contexts from the checked s (pointers into s's arrays). */
void sf_site_v3_view(const stridefix_site_t *s, sf_site_t *site);

#endif
