/* sf_params.h — every tunable of the estimator and the daemon, in one place.
 *
 * SF_PARAM_LIST is the single source: each row gives section, name, C type, default, min, max, unit
 * and meaning. From it come the sf_params_t struct (field `<section>_<name>`), the defaults, the
 * range checks, the config-file keys (`[section]` + `name = value`, see firmware/board/sf_config.h)
 * and the CONFIG message echo (key `section.name`). Adding a parameter is adding one row (PX4's
 * params yaml, in C). */
#ifndef SF_PARAMS_H
#define SF_PARAMS_H

#include <stddef.h>
#include <stdint.h>

/* Rows are grouped by concern, one macro per core module, so each module's parameters sit together.
 *        section   name                 type     default  min      max      unit     meaning */
#define SF_PARAMS_INIT(X)                                                                              \
    X(init,   x_m,                 double,  0.0,     -1e6,    1e6,     "m",     "start position x, map frame")  \
    X(init,   y_m,                 double,  0.0,     -1e6,    1e6,     "m",     "start position y, map frame")  \
    X(init,   heading_rad,         double,  0.0,     -7.0,    7.0,     "rad",   "start walking direction, CCW from +x") \
    X(init,   floor,               int32_t, 0,       -20,     200,     "",      "start floor index")

#define SF_PARAMS_PDR(X)                                                                               \
    X(pdr,    stride_m,            double,  0.70,    0.2,     1.5,     "m",     "fixed step length")            \
    X(pdr,    step_threshold_mps2, double,  1.0,     0.1,     10.0,    "m/s2",  "vertical acceleration peak needed for a step") \
    X(pdr,    step_min_interval_ms, int32_t, 300,    100,     2000,    "ms",    "refractory time between steps") \
    X(pdr,    gravity_tau_s,       double,  1.0,     0.05,    20.0,    "s",     "time constant of the gravity low-pass") \
    X(pdr,    accel_cutoff_hz,     double,  4.0,     0.5,     20.0,    "Hz",    "low-pass cut-off on vertical acceleration") \
    X(pdr,    max_gap_ms,          int32_t, 500,     20,      10000,   "ms",    "IMU gap beyond which integration restarts")

/* sf_attitude.h, sf_heading.h */
#define SF_PARAMS_ATTITUDE(X)

/* sf_steps.h, sf_stride.h */
#define SF_PARAMS_STEPS(X)

/* sf_activity.h, sf_floor.h */
#define SF_PARAMS_ACTIVITY(X)

#define SF_PARAMS_OUTPUT(X)                                                                            \
    X(output, pose_period_ms,      int32_t, 1000,    10,      60000,   "ms",    "POSE publish period between steps") \
    X(output, health_period_ms,    int32_t, 1000,    100,     60000,   "ms",    "HEALTH publish period (board time)")

#define SF_PARAM_LIST(X) \
    SF_PARAMS_INIT(X) SF_PARAMS_PDR(X) SF_PARAMS_ATTITUDE(X) SF_PARAMS_STEPS(X) SF_PARAMS_ACTIVITY(X) SF_PARAMS_OUTPUT(X)

typedef struct {
#define SF_PARAM_FIELD(sec, name, type, def, lo, hi, unit, text) type sec##_##name;
    SF_PARAM_LIST(SF_PARAM_FIELD)
#undef SF_PARAM_FIELD
} sf_params_t;

/* Number of rows, as a compile-time constant. */
#define SF_PARAM_COUNT_ONE(sec, name, type, def, lo, hi, unit, text) +1
enum { SF_PARAM_COUNT = 0 SF_PARAM_LIST(SF_PARAM_COUNT_ONE) };

typedef enum { sf_param_double, sf_param_int32 } sf_param_kind_t;

/* One row of SF_PARAM_LIST as data, for loaders and for the CONFIG echo. */
typedef struct {
    const char *section;
    const char *name;
    sf_param_kind_t kind;
    size_t offset; /* into sf_params_t */
    double default_value;
    double min_value;
    double max_value;
    const char *unit;
    const char *text;
} sf_param_desc_t;

extern const sf_param_desc_t sf_param_table[];
extern const size_t sf_param_count;

/* Fills every field with its default. */
void sf_params_default(sf_params_t *params);

/* The row for section/name, or NULL. */
const sf_param_desc_t *sf_param_find(const char *section, const char *name);

/* Sets one field; SF_ERANGE when value is outside [min, max] (field unchanged), SF_EINVAL when an
 * int32 field gets a value with a fractional part. */
int sf_param_set(sf_params_t *params, const sf_param_desc_t *desc, double value);

/* Reads one field as a double. */
double sf_param_get(const sf_params_t *params, const sf_param_desc_t *desc);

#endif
