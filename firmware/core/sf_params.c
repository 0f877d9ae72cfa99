/* sf_params.c — the parameter table generated from SF_PARAM_LIST, defaults and range checks. */
#include "sf_params.h"

#include <math.h>
#include <string.h>

#include "sf_error.h"

#define SF_PARAM_KIND_double sf_param_double
#define SF_PARAM_KIND_int32_t sf_param_int32

const sf_param_desc_t sf_param_table[] = {
#define SF_PARAM_ROW(sec, name, type, def, lo, hi, unit, text) \
    {#sec, #name, SF_PARAM_KIND_##type, offsetof(sf_params_t, sec##_##name), def, lo, hi, unit, text},
    SF_PARAM_LIST(SF_PARAM_ROW)
#undef SF_PARAM_ROW
};
const size_t sf_param_count = sizeof(sf_param_table) / sizeof(sf_param_table[0]);

void sf_params_default(sf_params_t *const params)
{
#define SF_PARAM_DEFAULT(sec, name, type, def, lo, hi, unit, text) params->sec##_##name = (type)(def);
    SF_PARAM_LIST(SF_PARAM_DEFAULT)
#undef SF_PARAM_DEFAULT
}

const sf_param_desc_t *sf_param_find(const char *const section, const char *const name)
{
    for (size_t i = 0; i < sf_param_count; i++) {
        if (strcmp(sf_param_table[i].section, section) == 0 && strcmp(sf_param_table[i].name, name) == 0) {
            return &sf_param_table[i];
        }
    }
    return NULL;
}

int sf_param_set(sf_params_t *const params, const sf_param_desc_t *const desc, const double value)
{
    if (params == NULL || desc == NULL) {
        return SF_EINVAL;
    }
    if (!(value >= desc->min_value && value <= desc->max_value)) { /* also rejects NaN */
        return SF_ERANGE;
    }
    unsigned char *const base = (unsigned char *)params + desc->offset;
    if (desc->kind == sf_param_int32) {
        if (value != floor(value)) {
            return SF_EINVAL;
        }
        const int32_t v = (int32_t)value;
        memcpy(base, &v, sizeof v);
    } else {
        memcpy(base, &value, sizeof value);
    }
    return SF_OK;
}

double sf_param_get(const sf_params_t *const params, const sf_param_desc_t *const desc)
{
    const unsigned char *const base = (const unsigned char *)params + desc->offset;
    if (desc->kind == sf_param_int32) {
        int32_t v;
        memcpy(&v, base, sizeof v);
        return (double)v;
    }
    double v;
    memcpy(&v, base, sizeof v);
    return v;
}
