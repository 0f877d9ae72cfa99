/* sf_particle_mem.c — see sf_particle_mem.h. */
#include "sf_particle_mem.h"

#include <stdlib.h>

#include "sf_error.h"

int sf_particle_mem_alloc(const sf_params_t *const p, const sf_site_t *const site, sf_particle_mem_t *const m)
{
    *m = (sf_particle_mem_t){0};
    const int32_t n = p->particle_count;
    m->states = calloc((size_t)n, sizeof *m->states);
    m->floors = calloc((size_t)n, sizeof *m->floors);
    const sf_floor_plan_t none = {0};
    const sf_floor_plan_t *const plan = site != NULL ? &site->plan : &none;
    m->grid_bytes = sf_wall_grid_bytes(plan, p->particle_grid_cell_m);
    m->grid_memory = m->grid_bytes > 0 ? malloc(m->grid_bytes) : NULL;
    if (m->states == NULL || m->floors == NULL || m->grid_memory == NULL) {
        sf_particle_mem_free(m);
        return SF_EIO;
    }
    m->capacity = n;
    if (site == NULL) { /* the grid would point at a plan on this stack: no walls, nothing to point at */
        sf_wall_grid_empty(&m->walls);
        return SF_OK;
    }
    const int rc = sf_wall_grid_build(&m->walls, plan, p->particle_grid_cell_m, m->grid_memory, m->grid_bytes);
    if (rc != SF_OK) {
        sf_particle_mem_free(m);
    }
    return rc;
}

void sf_particle_mem_free(sf_particle_mem_t *const m)
{
    free(m->states);
    free(m->floors);
    free(m->grid_memory);
    *m = (sf_particle_mem_t){0};
}
