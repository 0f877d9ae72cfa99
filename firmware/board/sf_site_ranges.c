/* sf_site_ranges.c — the site fields' physical ranges (see sf_site_ranges.h). */
#include "sf_site_ranges.h"

#include <math.h>
#include <stdbool.h>

#include "sf_cls.h"
#include "sf_error.h"
#include "sf_fingerprint.h"
#include "sf_floor.h"
#include "sf_lcm_walk.h"
#include "sf_site_ranges_table.h"

/* The table's count limits are the firmware's capacities: a site the loader accepts fits them (the
 * estimator refused a bigger one only when attaching it, as "value out of range" naming nothing). */
_Static_assert(SF_SITE_RANGE_MAX_n_floors == SF_FLOOR_CAPACITY, "site_ranges.tsv: n_floors max != SF_FLOOR_CAPACITY");
_Static_assert(SF_SITE_RANGE_MAX_n_ap == SF_FINGERPRINT_MAX_MAP_APS,
               "site_ranges.tsv: n_ap max != SF_FINGERPRINT_MAX_MAP_APS");
_Static_assert(SF_SITE_RANGE_MAX_n_contexts == SF_CONTROLLER_MAX_CONTEXTS,
               "site_ranges.tsv: n_contexts max != SF_CONTROLLER_MAX_CONTEXTS");

static bool outside(const double v, const double lo, const double hi, const bool nan_ok)
{
    return !(v >= lo && v <= hi) && !(nan_ok && isnan(v));
}

/* The refusal, in site_ranges.py's words: "<label> <i>: <field> = ..." or "<field>[<i>] = ..." for an
 * element (i >= 0), "<field> = ..." for a scalar (i < 0). */
static int refuse(const char *const name, char *const err, const size_t err_size, const char *const label,
                  const char *const field, const int32_t i, const double v, const double lo, const double hi,
                  const char *const unit)
{
    if (i < 0) {
        return sf_lcm_failf(err, err_size, name, SF_ERANGE, "%s = %g outside %g..%g%s", field, v, lo, hi, unit);
    }
    if (label == NULL) {
        return sf_lcm_failf(err, err_size, name, SF_ERANGE, "%s[%d] = %g outside %g..%g%s", field, (int)i, v, lo,
                            hi, unit);
    }
    return sf_lcm_failf(err, err_size, name, SF_ERANGE, "%s %d: %s = %g outside %g..%g%s", label, (int)i, field, v,
                        lo, hi, unit);
}

int sf_site_check_ranges(const stridefix_site_t *const s, const char *const name, char *const err,
                         const size_t err_size)
{
#define SCALAR(field, when, lo, hi, unit)                                                   \
    if ((when) && outside((double)s->field, (lo), (hi), false)) {                           \
        return refuse(name, err, err_size, NULL, #field, -1, (double)s->field, (lo), (hi), unit); \
    }
#define ARRAY(field, count, label, when, lo, hi, unit, nan_ok)                              \
    for (int32_t i = 0; (when) && i < (int32_t)(count); i++) {                              \
        if (outside((double)s->field[i], (lo), (hi), (nan_ok) != 0)) {                      \
            return refuse(name, err, err_size, (label), #field, i, (double)s->field[i], (lo), (hi), unit); \
        }                                                                                   \
    }
    SF_SITE_RANGES(SCALAR, ARRAY)
#undef SCALAR
#undef ARRAY
    return SF_OK;
}
