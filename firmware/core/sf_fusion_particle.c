/* sf_fusion_particle.c — the particle scheme's control (sf_fusion.h, "particle"): start, floor,
 * evidence, recovery and the audit, around the cloud of sf_particle.h. Read top to bottom like
 * sf_fusion_fix: floors, innovate, judge, apply, record. */
#include <math.h>

#include "sf_assert.h"
#include "sf_fusion_internal.h"

/* The fix's 1σ per axis. A Wi-Fi matcher's accuracy is a shape, not a σ (sf_ekf.h: on site2/F3 the
 * errors are ~15 m at claimed accuracies of a few metres): its R is the site's measured fix-error model
 * F + a²M as a whole (the cloud carries no correlated error), isotropic; the other sources state a σ. */
static double fix_sigma_m(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix)
{
    double var_m2 = fix->accuracy_m * fix->accuracy_m;
    if (fix->method == sf_fix_wifi) {
        double r_m2[3];
        sf_ekf_fix_total(&f->ekf, fix->accuracy_m, r_m2);
        var_m2 = 0.5 * (r_m2[0] + r_m2[2]);
    }
    return sqrt(fmax(var_m2, p->fusion_var_min_m2));
}

/* The published track into the scheme's own fields (x, y, var; floor_offset holds the track's floor):
 * the cloud's mean, unless that lies behind a wall from the track's last position on the same floor —
 * then the reachable part of the cloud (sf_particle_reachable), so the track never walks through a
 * wall. A start or a re-seed (`jump`) is a new position: taken as it is. */
static void mirror(sf_fusion_t *const f, sf_particle_summary_t *const s, const bool jump)
{
    sf_particle_t *const c = f->cloud;
    SF_ASSERT(c != NULL && c->seeded); /* a seeded cloud is mirrored, never a missing one */
    sf_particle_summary(c, s);
    double x = s->x_m, y = s->y_m;
    if (!jump && c->walls != NULL && f->floor_offset == (int32_t)s->floor &&
        sf_wall_grid_crosses(c->walls, s->floor, f->x_m, f->y_m, x, y)) {
        if (sf_particle_reachable(c, s->floor, f->x_m, f->y_m, s->x_m, s->y_m, &x, &y)) {
            c->detours++;
        } else {
            c->jumps++; /* too little of the cloud within reach (SF_PARTICLE_REACH_SHARE): follow it */
        }
    }
    f->x_m = x;
    f->y_m = y;
    f->floor_offset = (int32_t)s->floor;
    f->var_m2 = 0.5 * (s->cov_m2[0] + s->cov_m2[2]);
}

void sf_fusion_particle_init_at(sf_fusion_t *const f, const sf_params_t *const p, const double x_m, const double y_m,
                                const double sigma_m, const int16_t baro_floor)
{
    if (f->cloud != NULL) {
        sf_particle_seed(f->cloud, p, x_m, y_m, sigma_m, baro_floor, false);
        sf_particle_summary_t s;
        mirror(f, &s, true);
    }
}

void sf_fusion_particle_step(sf_fusion_t *const f, const sf_params_t *const p, const double dx_m, const double dy_m,
                             const double length_m, const int16_t baro_floor)
{
    if (f->cloud == NULL || !f->cloud->seeded) {
        return;
    }
    sf_particle_step(f->cloud, p, length_m, atan2(dy_m, dx_m), baro_floor);
    sf_particle_summary_t s;
    mirror(f, &s, false);
}

/* Re-seeds around the fix (σ = its accuracy; bias and scale kept), α = 1. */
static void reseed(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix, const int16_t floor,
                   sf_fix_audit_t *const audit)
{
    sf_particle_seed(f->cloud, p, fix->x_m, fix->y_m, fix_sigma_m(f, p, fix), floor, true);
    audit->alpha = 1.0;
    audit->accepted = true;
    audit->reason = sf_fix_reason_recovery;
    f->recoveries++;
}

void sf_fusion_particle_fix(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                            const int16_t baro_floor, const bool between_floors, sf_fix_audit_t *const audit)
{
    sf_particle_t *const c = f->cloud;
    SF_ASSERT(f->fixes > 0 && isfinite(fix->accuracy_m)); /* sf_fusion_fix_on_floor counted and checked it */
    const double sigma_m = fix_sigma_m(f, p, fix), r_m2 = sigma_m * sigma_m;
    sf_particle_summary_t s;
    if (c == NULL) {
        audit->reason = sf_fix_reason_not_initialised; /* no memory for a cloud: no position ever */
        return;
    }
    /* control: start */
    if (!f->initialised || !c->seeded) {
        sf_particle_seed(c, p, fix->x_m, fix->y_m, sigma_m, baro_floor, false);
        f->initialised = true;
        f->initialisations++;
        f->rejections = 0;
        f->last_fix_t_us = fix->t_us;
        mirror(f, &s, true);
        audit->innovation_var_m2 = r_m2;
        audit->alpha = 1.0;
        audit->accepted = true;
        audit->reason = sf_fix_reason_initialised;
        return;
    }
    /* fusion: floors at the particles' positions, then ν against the cloud's mean, S = cov + R */
    sf_particle_floors(c, baro_floor);
    sf_particle_summary(c, &s);
    const double nu_x = fix->x_m - s.x_m, nu_y = fix->y_m - s.y_m;
    const double sxx = s.cov_m2[0] + r_m2, sxy = s.cov_m2[1], syy = s.cov_m2[2] + r_m2;
    const double det = sxx * syy - sxy * sxy, gate = p->fusion_gate_sigma;
    const double nis = det > 0.0 ? (syy * nu_x * nu_x - 2.0 * sxy * nu_x * nu_y + sxx * nu_y * nu_y) / det : INFINITY;
    audit->innovation_m[0] = nu_x;
    audit->innovation_m[1] = nu_y;
    audit->innovation_var_m2 = 0.5 * (sxx + syy);
    audit->test_ratio = nis / (gate * gate);

    /* control: judge, then apply */
    if (between_floors) {
        audit->reason = sf_fix_reason_floor_mismatch;
        f->rejected_floor++; /* not the scheme's divergence: no step toward recovery */
        return;
    }
    /* every source as its own likelihood; a Wi-Fi fix's σ is the site's whole fix-error model (white and
     * correlated parts: carrying the correlated part per particle, Rao-Blackwellised like the ekf's c,
     * cost site1/F2 1.1 m of mean error, 4.65 → 5.75 m — the cloud then barely moved on the fixes) */
    const double evidence = sf_particle_evidence(c, fix->x_m, fix->y_m, sigma_m);
    if (evidence >= exp(-0.5 * gate * gate)) {
        double ess_after;
        audit->alpha = sf_particle_update(c, p, fix->x_m, fix->y_m, sigma_m, &ess_after);
        if (ess_after < p->particle_reseed_ess_ratio * (double)c->n) {
            reseed(f, p, fix, s.floor, audit); /* collapsed: the cloud no longer samples the posterior */
        } else {
            audit->accepted = true;
            audit->reason = sf_fix_reason_accepted;
            f->accepted++;
        }
    } else if (sf_fix_is_known_position(fix->method)) {
        reseed(f, p, fix, s.floor, audit); /* a known position: the whole cloud goes there */
    } else if (f->rejections >= p->fusion_max_rejections) {
        /* the fixes keep landing where no particle is: a new hypothesis beside the old one */
        sf_particle_inject(c, fix->x_m, fix->y_m, sigma_m, s.floor, p->particle_recovery_share);
        audit->alpha = p->particle_recovery_share;
        audit->accepted = true;
        audit->reason = sf_fix_reason_recovery;
        f->recoveries++;
    } else {
        audit->reason = sf_fix_reason_gate;
        f->rejected_gate++;
        f->rejections++;
        return;
    }
    f->last_fix_t_us = fix->t_us;
    f->rejections = 0;
    mirror(f, &s, audit->reason == sf_fix_reason_recovery && audit->alpha >= 1.0); /* a whole re-seed jumps */
}

bool sf_fusion_particle_pose(const sf_fusion_t *const f, sf_pose_t *const pose)
{
    if (f->cloud == NULL || !f->cloud->seeded) {
        return false;
    }
    sf_particle_summary_t s;
    sf_particle_summary(f->cloud, &s);
    pose->x_m = f->x_m; /* the walkable track (mirror), not the bare mean */
    pose->y_m = f->y_m;
    pose->floor = s.floor;
    pose->cov_m2[0] = s.cov_m2[0];
    pose->cov_m2[1] = s.cov_m2[1];
    pose->cov_m2[2] = s.cov_m2[2];
    pose->sigma_m = sqrt(0.5 * (s.cov_m2[0] + s.cov_m2[2]));
    pose->heading_bias_rad = s.bias_rad;
    pose->stride_scale = s.scale;
    pose->heading_rad = atan2(sin(pose->heading_rad + s.bias_rad), cos(pose->heading_rad + s.bias_rad));
    pose->ess = s.ess;
    return true;
}
