/* sf_fusion_internal.h — what the fusion's own files share (not a public API): the scheme registry's
 * row type (sf_fusion_registry.c) and the particle scheme's control (sf_fusion_particle.c), dispatched
 * from sf_fusion.c. */
#ifndef SF_FUSION_INTERNAL_H
#define SF_FUSION_INTERNAL_H

#include <stdbool.h>

#include "sf_fusion.h"

/* How a scheme uses steps and fixes (sf_fusion.h): dead reckoning only (fixes initialise, then are
 * ignored), following the fixes (no prediction, no gate), predicting and blending gated fixes with
 * the row's gain law, the error-state filter of sf_ekf.h (its own prediction, gain and R), or the
 * particle filter of sf_particle.h (its own everything, sf_fusion_particle.c). */
typedef enum { mode_dead_reckoning = 1, mode_follow_fixes, mode_blend, mode_ekf, mode_particle } sf_scheme_mode_t;

typedef double (*sf_alpha_law_t)(const sf_fusion_t *f, const sf_params_t *p, const sf_fix_t *fix, double r_m2,
                                 sf_fix_audit_t *audit);

typedef struct {
    sf_scheme_mode_t mode;
    sf_alpha_law_t alpha; /* mode_blend: α of an accepted fix */
    bool kalman_variance; /* var ← (1 − α)·var instead of the Joseph form */
} sf_scheme_row_t;

/* The registry row of a scheme in [0, sf_scheme_count). */
const sf_scheme_row_t *sf_fusion_row(int scheme);

/* The particle scheme (f's mode is mode_particle): the same contracts as the public calls. */
void sf_fusion_particle_init_at(sf_fusion_t *f, const sf_params_t *p, double x_m, double y_m, double sigma_m,
                                int16_t baro_floor);
void sf_fusion_particle_step(sf_fusion_t *f, const sf_params_t *p, double dx_m, double dy_m, double length_m,
                             int16_t baro_floor);
void sf_fusion_particle_fix(sf_fusion_t *f, const sf_params_t *p, const sf_fix_t *fix, int16_t baro_floor,
                            bool between_floors, sf_fix_audit_t *audit);
bool sf_fusion_particle_pose(const sf_fusion_t *f, sf_pose_t *pose);

#endif
