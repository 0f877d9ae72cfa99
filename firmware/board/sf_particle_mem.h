/* sf_particle_mem.h — the particle scheme's memory for a run (sf_particle.h, sf_wall_grid.h): one heap
 * block for particle.count particles (SF_PARTICLE_BYTES_PER = 34 B each: 34 kB at 1 000) and one for
 * the site's wall index (sf_wall_grid_bytes at particle.grid_cell_m; 4 B without walls), allocated once
 * at start-up like the matcher's workspace (sf_workspace.h), then handed to the core. */
#ifndef SF_PARTICLE_MEM_H
#define SF_PARTICLE_MEM_H

#include <stddef.h>

#include "sf_params.h"
#include "sf_particle.h"
#include "sf_radiomap.h"
#include "sf_wall_grid.h"

typedef struct {
    sf_particle_state_t *states;
    int16_t *floors;
    int32_t capacity;
    sf_wall_grid_t walls;
    void *grid_memory;
    size_t grid_bytes;
} sf_particle_mem_t;

/* Allocates and builds (site NULL: no walls). SF_OK, SF_EIO when out of memory, or the error of
 * sf_wall_grid_build; on error nothing stays allocated. */
int sf_particle_mem_alloc(const sf_params_t *p, const sf_site_t *site, sf_particle_mem_t *m);

/* Frees what sf_particle_mem_alloc allocated; a zeroed struct is fine. */
void sf_particle_mem_free(sf_particle_mem_t *m);

#endif
