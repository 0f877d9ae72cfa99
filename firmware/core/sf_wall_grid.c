/* sf_wall_grid.c — see sf_wall_grid.h for the model: layout per floor, the conservative scan line shared
 * by build and query, the exact predicate. */
#include "sf_wall_grid.h"

#include <math.h>
#include <string.h>

#include "sf_error.h"

/* ---- the exact predicate ------------------------------------------------------------------------- */

static double min2(const double a, const double b)
{
    return a < b ? a : b; /* fmin is a libm call here; no NaN reaches these */
}

static double max2(const double a, const double b)
{
    return a > b ? a : b;
}

/* Twice the signed area of (a, b, c): > 0 when c is left of a → b. */
static double orient(const double ax, const double ay, const double bx, const double by, const double cx,
                     const double cy)
{
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

/* c, known collinear with a — b, lies within its closed bounding box. */
static bool within(const double ax, const double ay, const double bx, const double by, const double cx,
                   const double cy)
{
    return min2(ax, bx) <= cx && cx <= max2(ax, bx) && min2(ay, by) <= cy && cy <= max2(ay, by);
}

bool sf_wall_segments_cross(const double p0x, const double p0y, const double p1x, const double p1y,
                            const double q0x, const double q0y, const double q1x, const double q1y)
{
    if (p0x == p1x && p0y == p1y) {
        return false; /* a zero-length step goes nowhere: (p0, p0] is empty */
    }
    if (max2(p0x, p1x) < min2(q0x, q1x) || max2(q0x, q1x) < min2(p0x, p1x) || max2(p0y, p1y) < min2(q0y, q1y) ||
        max2(q0y, q1y) < min2(p0y, p1y)) {
        return false; /* closed boxes apart: no common point (exact, and most walls of a cell) */
    }
    const double d1 = orient(q0x, q0y, q1x, q1y, p0x, p0y);
    const double d2 = orient(q0x, q0y, q1x, q1y, p1x, p1y);
    const double d3 = orient(p0x, p0y, p1x, p1y, q0x, q0y);
    const double d4 = orient(p0x, p0y, p1x, p1y, q1x, q1y);
    if (d1 == 0.0 && within(q0x, q0y, q1x, q1y, p0x, p0y)) {
        /* the step starts on the wall: it crosses only by sliding along it beyond its start */
        if (d2 != 0.0) {
            return false;
        }
        const double ex = p1x - p0x, ey = p1y - p0y;
        const double t0 = (q0x - p0x) * ex + (q0y - p0y) * ey, t1 = (q1x - p0x) * ex + (q1y - p0y) * ey;
        return fmax(t0, t1) > 0.0;
    }
    if (((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))) {
        return true; /* proper crossing */
    }
    return (d2 == 0.0 && within(q0x, q0y, q1x, q1y, p1x, p1y)) || (d3 == 0.0 && within(p0x, p0y, p1x, p1y, q0x, q0y)) ||
           (d4 == 0.0 && within(p0x, p0y, p1x, p1y, q1x, q1y));
}

/* ---- the scan line ------------------------------------------------------------------------------- */

static int32_t clamp_i(const double v, const int32_t hi)
{
    return v < 0.0 ? 0 : (v > (double)hi ? hi : (int32_t)v);
}

/* Rows [*r0, *r1] the segment (grid units) reaches; false when none is inside the grid. */
static bool seg_rows(const sf_wall_floor_grid_t *const g, const double av, const double bv, int32_t *const r0,
                     int32_t *const r1)
{
    const double lo = floor(min2(av, bv) - SF_WALL_GRID_PAD), hi = floor(max2(av, bv) + SF_WALL_GRID_PAD);
    if (hi < 0.0 || lo > (double)(g->ny - 1)) {
        return false;
    }
    *r0 = clamp_i(lo, g->ny - 1);
    *r1 = clamp_i(hi, g->ny - 1);
    return true;
}

/* Columns [*c0, *c1] of row r the segment (grid units) reaches; false when none is inside the grid. */
static bool seg_cols(const sf_wall_floor_grid_t *const g, const double au, const double av, const double bu,
                     const double bv, const int32_t r, int32_t *const c0, int32_t *const c1)
{
    double ulo = min2(au, bu), uhi = max2(au, bu);
    if (av != bv) { /* the part of the segment inside the row's band, padded */
        double t0 = ((double)r - SF_WALL_GRID_PAD - av) / (bv - av);
        double t1 = ((double)r + 1.0 + SF_WALL_GRID_PAD - av) / (bv - av);
        if (t0 > t1) {
            const double t = t0;
            t0 = t1;
            t1 = t;
        }
        t0 = max2(t0, 0.0);
        t1 = min2(t1, 1.0);
        const double u0 = au + t0 * (bu - au), u1 = au + t1 * (bu - au);
        ulo = min2(u0, u1);
        uhi = max2(u0, u1);
    }
    const double lo = floor(ulo - SF_WALL_GRID_PAD), hi = floor(uhi + SF_WALL_GRID_PAD);
    if (hi < 0.0 || lo > (double)(g->nx - 1)) {
        return false;
    }
    *c0 = clamp_i(lo, g->nx - 1);
    *c1 = clamp_i(hi, g->nx - 1);
    return true;
}

/* ---- layout -------------------------------------------------------------------------------------- */

static bool wall_ok(const sf_floor_plan_t *const plan, const int32_t i)
{
    return isfinite(plan->x0_m[i]) && isfinite(plan->y0_m[i]) && isfinite(plan->x1_m[i]) && isfinite(plan->y1_m[i]);
}

static int floor_slot(const sf_wall_grid_t *const g, const int16_t floor)
{
    for (int i = 0; i < g->n_floors; i++) {
        if (g->floors[i].floor == floor) {
            return i;
        }
    }
    return -1;
}

/* Floors (ascending), their boxes and cell sizes, into *g (first/seg unset). */
static void layout(sf_wall_grid_t *const g, const sf_floor_plan_t *const plan, const double cell_m)
{
    *g = (sf_wall_grid_t){.plan = plan};
    double box[SF_WALL_GRID_MAX_FLOORS][4];
    for (int32_t i = 0; i < plan->n_walls; i++) {
        if (!wall_ok(plan, i)) {
            g->bad_segments++;
            continue;
        }
        const int16_t fl = plan->floor[i];
        int s = floor_slot(g, fl);
        if (s < 0) {
            if (g->n_floors == SF_WALL_GRID_MAX_FLOORS) {
                g->floors_dropped++;
                continue;
            }
            s = g->n_floors++;
            while (s > 0 && g->floors[s - 1].floor > fl) { /* keep them ascending */
                g->floors[s] = g->floors[s - 1];
                memcpy(box[s], box[s - 1], sizeof box[s]);
                s--;
            }
            g->floors[s] = (sf_wall_floor_grid_t){.floor = fl};
            box[s][0] = box[s][1] = INFINITY;
            box[s][2] = box[s][3] = -INFINITY;
        }
        box[s][0] = fmin(box[s][0], fmin(plan->x0_m[i], plan->x1_m[i]));
        box[s][1] = fmin(box[s][1], fmin(plan->y0_m[i], plan->y1_m[i]));
        box[s][2] = fmax(box[s][2], fmax(plan->x0_m[i], plan->x1_m[i]));
        box[s][3] = fmax(box[s][3], fmax(plan->y0_m[i], plan->y1_m[i]));
    }
    for (int s = 0; s < g->n_floors; s++) {
        sf_wall_floor_grid_t *const fg = &g->floors[s];
        double c = cell_m;
        for (;;) { /* one cell of margin each side; grow the cells until the grid fits */
            const double nx = floor((box[s][2] - box[s][0]) / c) + 3.0, ny = floor((box[s][3] - box[s][1]) / c) + 3.0;
            if (nx * ny <= (double)SF_WALL_GRID_MAX_CELLS) {
                fg->nx = (int32_t)nx;
                fg->ny = (int32_t)ny;
                break;
            }
            c *= 1.0 + sqrt(nx * ny / (double)SF_WALL_GRID_MAX_CELLS);
        }
        fg->cell_m = c;
        fg->x0_m = box[s][0] - c;
        fg->y0_m = box[s][1] - c;
    }
}

/* Walks wall i's cells on its floor's grid: counts them into count[cell + 1], or writes i at
 * seg[cursor[cell]++] (count NULL), or only counts them (both NULL). Returns the number of cells. */
static int64_t raster(const sf_wall_grid_t *const g, const int32_t i, int32_t *const count, int32_t *const cursor,
                      int32_t *const seg)
{
    const sf_floor_plan_t *const plan = g->plan;
    const int s = floor_slot(g, plan->floor[i]);
    if (s < 0 || !wall_ok(plan, i)) {
        return 0;
    }
    const sf_wall_floor_grid_t *const fg = &g->floors[s];
    const double au = (plan->x0_m[i] - fg->x0_m) / fg->cell_m, av = (plan->y0_m[i] - fg->y0_m) / fg->cell_m;
    const double bu = (plan->x1_m[i] - fg->x0_m) / fg->cell_m, bv = (plan->y1_m[i] - fg->y0_m) / fg->cell_m;
    int32_t r0, r1, c0, c1;
    int64_t n = 0;
    if (!seg_rows(fg, av, bv, &r0, &r1)) {
        return 0;
    }
    for (int32_t r = r0; r <= r1; r++) {
        if (!seg_cols(fg, au, av, bu, bv, r, &c0, &c1)) {
            continue;
        }
        for (int32_t c = c0; c <= c1; c++) {
            const int32_t cell = r * fg->nx + c;
            if (count != NULL) {
                count[cell + 1]++;
            } else if (cursor != NULL) {
                seg[cursor[cell]++] = i;
            }
            n++;
        }
    }
    return n;
}

size_t sf_wall_grid_bytes(const sf_floor_plan_t *const plan, const double cell_m)
{
    if (plan == NULL || !(isfinite(cell_m) && cell_m > 0.0)) {
        return 0;
    }
    sf_wall_grid_t g;
    layout(&g, plan, cell_m);
    size_t words = 1;
    for (int s = 0; s < g.n_floors; s++) {
        words += (size_t)g.floors[s].nx * (size_t)g.floors[s].ny + 1;
    }
    for (int32_t i = 0; i < plan->n_walls; i++) {
        words += (size_t)raster(&g, i, NULL, NULL, NULL);
    }
    return words * sizeof(int32_t);
}

void sf_wall_grid_empty(sf_wall_grid_t *const grid)
{
    *grid = (sf_wall_grid_t){0};
}

int sf_wall_grid_build(sf_wall_grid_t *const grid, const sf_floor_plan_t *const plan, const double cell_m,
                       void *const memory, const size_t bytes)
{
    if (grid == NULL || memory == NULL) {
        return SF_EINVAL;
    }
    const size_t need = sf_wall_grid_bytes(plan, cell_m);
    if (need == 0 || bytes < need) {
        return SF_EINVAL;
    }
    sf_wall_grid_t g;
    layout(&g, plan, cell_m);
    int32_t *const words = (int32_t *)memory;
    memset(words, 0, need);
    /* cell heads per floor, then each floor's ids */
    size_t at = 0;
    int32_t *heads[SF_WALL_GRID_MAX_FLOORS];
    int32_t *segs[SF_WALL_GRID_MAX_FLOORS];
    for (int s = 0; s < g.n_floors; s++) {
        heads[s] = words + at;
        at += (size_t)g.floors[s].nx * (size_t)g.floors[s].ny + 1;
    }
    for (int32_t i = 0; i < plan->n_walls; i++) { /* counts into heads[cell + 1] */
        const int s = floor_slot(&g, plan->floor[i]);
        if (s >= 0) {
            (void)raster(&g, i, heads[s], NULL, NULL);
        }
    }
    for (int s = 0; s < g.n_floors; s++) { /* prefix sums: first[] */
        const int32_t cells = g.floors[s].nx * g.floors[s].ny;
        for (int32_t c = 0; c < cells; c++) {
            heads[s][c + 1] += heads[s][c];
        }
        g.floors[s].first = heads[s];
        segs[s] = words + at;
        g.floors[s].seg = segs[s];
        at += (size_t)heads[s][cells];
    }
    /* fill: shifted up by one, first[c + 1] is cell c's start and serves as its cursor; each cursor
     * ends at its cell's end, the next cell's start, which is what first[c + 1] must hold */
    for (int s = 0; s < g.n_floors; s++) {
        int32_t *const first = heads[s];
        for (int32_t c = g.floors[s].nx * g.floors[s].ny; c > 0; c--) {
            first[c] = first[c - 1];
        }
        for (int32_t i = 0; i < plan->n_walls; i++) {
            if (floor_slot(&g, plan->floor[i]) == s) {
                (void)raster(&g, i, NULL, first + 1, segs[s]);
            }
        }
    }
    *grid = g;
    return SF_OK;
}

bool sf_wall_grid_crosses(const sf_wall_grid_t *const grid, const int16_t floor, const double x0_m,
                          const double y0_m, const double x1_m, const double y1_m)
{
    const int s = grid->n_floors > 0 ? floor_slot(grid, floor) : -1;
    if (s < 0) {
        return false;
    }
    const sf_wall_floor_grid_t *const fg = &grid->floors[s];
    const sf_floor_plan_t *const plan = grid->plan;
    const double au = (x0_m - fg->x0_m) / fg->cell_m, av = (y0_m - fg->y0_m) / fg->cell_m; /* as raster() */
    const double bu = (x1_m - fg->x0_m) / fg->cell_m, bv = (y1_m - fg->y0_m) / fg->cell_m;
    int32_t r0, r1, c0, c1;
    if (!seg_rows(fg, av, bv, &r0, &r1)) {
        return false;
    }
    for (int32_t r = r0; r <= r1; r++) {
        if (!seg_cols(fg, au, av, bu, bv, r, &c0, &c1)) {
            continue;
        }
        for (int32_t k = fg->first[r * fg->nx + c0]; k < fg->first[r * fg->nx + c1 + 1]; k++) {
            const int32_t i = fg->seg[k];
            if (sf_wall_segments_cross(x0_m, y0_m, x1_m, y1_m, plan->x0_m[i], plan->y0_m[i], plan->x1_m[i],
                                       plan->y1_m[i])) {
                return true;
            }
        }
    }
    return false;
}
