/* sf_site_ranges.h — the site fields' physical ranges (firmware/site_ranges.tsv, the one table both
 * site readers check; analyzer/stridefix_analyzer/io/site_ranges.py is the Python side), for sf_site.c
 * (not a public API).
 *
 * A finite but absurd value (a map rotation of 3e38°, a reference point 3e38 m from the origin) passes
 * every finiteness rule; this check, run after all the others, refuses each numeric field outside the
 * range a building can have, naming the field and the element in the Python reader's words:
 * "rp 2: rp_x_m = 3e+38 outside -100000..100000 m", "map_rotation_deg = 3e+38 outside -360..360 deg",
 * "floor_height_m[2] = 1e+09 outside -1000..10000 m". Cost O(total array length), no allocation. */
#ifndef SF_SITE_RANGES_H
#define SF_SITE_RANGES_H

#include <stddef.h>

#include "stridefix_site_t.h"

/* SF_OK, or SF_ERANGE with "<name>: <what>" in err for the first value outside its range, in the
 * table's order. The array lengths are the decoded counts (checked by the payload walk). */
int sf_site_check_ranges(const stridefix_site_t *s, const char *name, char *err, size_t err_size);

#endif
