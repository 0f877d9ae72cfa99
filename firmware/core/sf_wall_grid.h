/* sf_wall_grid.h — a uniform grid index over a floor plan's wall segments, so that asking "does this
 * step cross a wall?" costs the same in a shed and in an airport (the particle filter, sf_particle.h).
 *
 * Model. Per floor of the plan (sf_floor_plan_t, sf_radiomap.h; map frame [m]) one grid of square cells
 * of side cell_m over the bounding box of that floor's walls; each cell lists every wall that touches
 * it (compressed rows: first[cell] .. first[cell+1]−1 index seg[]). The walls themselves stay in the
 * plan (caller-owned, must outlive the grid): the index holds only int32 ids.
 *
 * Rasterisation (build) and traversal (query) are the same conservative scan line: for every row of
 * cells the segment's v-range reaches, the u-range of its points inside that row, both padded by
 * SF_WALL_GRID_PAD cells. A cell's closed box that holds a point of a segment is always visited, so the
 * cell holding an intersection point is both in the wall's list and on the step's path: the grid never
 * misses a crossing the brute force finds (test_wall_grid.c checks equality on random segments). The
 * step visits ~(L/cell_m + 2) cells: its cost follows its length and the local wall density, not the
 * building's size.
 *
 * Exact test (sf_wall_segments_cross, the brute force's predicate too): orientations in double. The
 * step is the half-open segment (start, end]: touching counts as crossing — an end on a wall, a wall's
 * end on the step, a step through the shared end point of two walls (a corner: no zero-width leak),
 * sliding along a wall (collinear overlap) — because walls are closed; only the start point is
 * excluded, so a particle that ever sits exactly on a wall (a re-seed, the keep-the-cloud fallback of
 * sf_particle.h) may leave it. Two walls meeting at a corner share the orientation of the corner
 * against the step (the same arguments give the same rounding), so a step through a corner crosses
 * exactly one of them, whatever the rounding. Zero-length steps cross nothing; zero-length walls are
 * points, crossed when the step ends on them or passes through them.
 *
 * Cell size: cell_m (the particle.grid_cell_m parameter); a floor whose grid would exceed
 * SF_WALL_GRID_MAX_CELLS cells gets larger cells (stated in the grid: floors[i].cell_m). Floors beyond
 * SF_WALL_GRID_MAX_FLOORS distinct ones are dropped (counted: floors_dropped); walls with a non-finite
 * coordinate are skipped (counted: bad_segments).
 *
 * Memory: the caller's block of sf_wall_grid_bytes() bytes = 4 B × Σ over floors (cells + 1 + wall-cell
 * incidences), e.g. the bench's 5 000-wall floor of 200 m × 100 m at 2 m cells: ≈ 5 000 cells and
 * ≈ 15 000 incidences ≈ 80 kB; plus sizeof(sf_wall_grid_t) ≤ 1 KiB (checked). Cost: build O(walls ×
 * cells touched + cells); query O(cells on the step's path × walls per cell). No heap, no I/O.
 * Errors: sf_wall_grid_build returns SF_OK, SF_EINVAL (NULL, bytes smaller than sf_wall_grid_bytes). */
#ifndef SF_WALL_GRID_H
#define SF_WALL_GRID_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sf_radiomap.h"

#define SF_WALL_GRID_MAX_FLOORS 16
#define SF_WALL_GRID_MAX_CELLS (1 << 20) /* per floor: 4 MiB of cell heads at most */
#define SF_WALL_GRID_PAD 1e-3             /* of a cell, both ways */

typedef struct {
    int16_t floor;
    int32_t nx, ny;      /* cells along x, y */
    double x0_m, y0_m;   /* the grid's lower-left corner */
    double cell_m;       /* side of a cell */
    const int32_t *first; /* [nx·ny + 1] */
    const int32_t *seg;   /* [first[nx·ny]] wall ids of the plan */
} sf_wall_floor_grid_t;

typedef struct {
    const sf_floor_plan_t *plan;
    int32_t n_floors; /* floors with walls, ascending */
    sf_wall_floor_grid_t floors[SF_WALL_GRID_MAX_FLOORS];
    uint32_t bad_segments;
    uint32_t floors_dropped;
} sf_wall_grid_t;
_Static_assert(sizeof(sf_wall_grid_t) <= 1024, "sf_wall_grid.h promises at most 1 KiB");

/* Bytes of index memory the plan needs at that cell size (≥ 4; 4 for a plan without walls).
 * 0 for a NULL plan or a cell size that is not finite and > 0. */
size_t sf_wall_grid_bytes(const sf_floor_plan_t *plan, double cell_m);

/* Builds the index into memory (at least sf_wall_grid_bytes bytes, aligned for int32_t). The plan must
 * outlive the grid. SF_OK or SF_EINVAL (grid untouched). */
int sf_wall_grid_build(sf_wall_grid_t *grid, const sf_floor_plan_t *plan, double cell_m, void *memory,
                       size_t bytes);

/* An empty grid (no walls anywhere: nothing is ever crossed). */
void sf_wall_grid_empty(sf_wall_grid_t *grid);

/* Whether the step (x0, y0) → (x1, y1) on floor crosses a wall of that floor (see the header). */
bool sf_wall_grid_crosses(const sf_wall_grid_t *grid, int16_t floor, double x0_m, double y0_m, double x1_m,
                          double y1_m);

/* The exact predicate for one step (p0 → p1, half-open) against one wall (q0 — q1, closed). */
bool sf_wall_segments_cross(double p0x, double p0y, double p1x, double p1y, double q0x, double q0y, double q1x,
                            double q1y);

#endif
