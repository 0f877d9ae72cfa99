/* test_site_v2.c — the version-2 content of a site file (geo-reference, walls, ports, BLE beacons)
 * reaches the core view (sf_site_t.geo/plan/ports/beacons) with every value the analyzer's writer put
 * there (tests/vectors/gen_site_vectors.py: site.sfsite and its dump site_v2.txt), and a site without
 * that content loads with empty views. The rules' rejections are test_site.c's variants. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_radiomap.h"
#include "sf_site.h"

#ifndef SF_SITE_VECTORS_DIR
#error "SF_SITE_VECTORS_DIR must name the directory gen_site_vectors.py wrote"
#endif

#define MAX_VALUES 32

typedef struct {
    const char *name;
    int n;
    double v[MAX_VALUES];
} row_t;

static row_t rows[32];
static int n_rows;

static void load_rows(void)
{
    n_rows = 0;
    FILE *const f = fopen(SF_SITE_VECTORS_DIR "/site_v2.txt", "r");
    assert_non_null(f);
    static char lines[32][1024];
    while (n_rows < 32 && fgets(lines[n_rows], sizeof lines[0], f) != NULL) {
        char *const line = lines[n_rows];
        line[strcspn(line, "\n")] = '\0';
        char *sp = strchr(line, ' ');
        row_t *const r = &rows[n_rows++];
        r->name = line;
        r->n = 0;
        if (sp == NULL) {
            continue;
        }
        *sp = '\0';
        const char *s = sp + 1;
        for (;;) {
            char *end = NULL;
            const double v = strtod(s, &end); /* "nan" parses to NaN; ids < 2^53 are exact doubles */
            if (end == s) {
                break;
            }
            assert_true(r->n < MAX_VALUES);
            r->v[r->n++] = v;
            s = end;
        }
    }
    fclose(f);
    assert_int_equal(n_rows, 21); /* 5 scalars + 16 arrays of site_t.lcm's version-2 fields */
}

static const row_t *row(const char *const name)
{
    for (int i = 0; i < n_rows; i++) {
        if (strcmp(rows[i].name, name) == 0) {
            return &rows[i];
        }
    }
    fail_msg("site_v2.txt has no %s", name);
    return NULL;
}

static int same(const double a, const double b)
{
    return (isnan(a) && isnan(b)) || a == b;
}

#define EXPECT_ARRAY(field, count, array)                                                                   \
    do {                                                                                                    \
        const row_t *const r_ = row(field);                                                                 \
        assert_int_equal(r_->n, (count));                                                                   \
        for (int i_ = 0; i_ < r_->n; i_++) {                                                                \
            if (!same((double)(array)[i_], r_->v[i_])) {                                                    \
                fail_msg("%s[%d] = %g, file says %g", field, i_, (double)(array)[i_], r_->v[i_]);           \
            }                                                                                               \
        }                                                                                                   \
    } while (0)

static void test_v2_view(void **state)
{
    (void)state;
    load_rows();
    sf_site_store_t store;
    sf_site_t site;
    char err[512] = "";
    const int rc = sf_site_load(SF_SITE_VECTORS_DIR "/site.sfsite", &store, &site, err, sizeof err);
    if (rc != SF_OK) {
        fail_msg("load: %d %s", rc, err);
    }
    assert_true(site.geo.valid);
    assert_true(site.geo.origin_lat_deg == store.msg.origin_lat_deg);
    assert_true(site.geo.origin_lon_deg == store.msg.origin_lon_deg);
    assert_true(site.geo.origin_alt_m == row("origin_alt_m")->v[0]);
    assert_true(site.geo.rotation_deg == row("geo_rotation_deg")->v[0]);
    const sf_floor_plan_t *const p = &site.plan;
    assert_true(p->n_walls > 0);
    EXPECT_ARRAY("wall_x0_m", p->n_walls, p->x0_m);
    EXPECT_ARRAY("wall_y0_m", p->n_walls, p->y0_m);
    EXPECT_ARRAY("wall_x1_m", p->n_walls, p->x1_m);
    EXPECT_ARRAY("wall_y1_m", p->n_walls, p->y1_m);
    EXPECT_ARRAY("wall_floor", p->n_walls, p->floor);
    const sf_ports_t *const q = &site.ports;
    assert_true(q->n_ports > 0);
    EXPECT_ARRAY("port_kind", q->n_ports, q->kind);
    EXPECT_ARRAY("port_x_m", q->n_ports, q->x_m);
    EXPECT_ARRAY("port_y_m", q->n_ports, q->y_m);
    EXPECT_ARRAY("port_radius_m", q->n_ports, q->radius_m);
    EXPECT_ARRAY("port_floor_lo", q->n_ports, q->floor_lo);
    EXPECT_ARRAY("port_floor_hi", q->n_ports, q->floor_hi);
    const sf_beacons_t *const b = &site.beacons;
    assert_true(b->n_beacons > 0);
    EXPECT_ARRAY("beacon_id", b->n_beacons, b->id);
    EXPECT_ARRAY("beacon_x_m", b->n_beacons, b->x_m);
    EXPECT_ARRAY("beacon_y_m", b->n_beacons, b->y_m);
    EXPECT_ARRAY("beacon_floor", b->n_beacons, b->floor);
    EXPECT_ARRAY("beacon_rssi_1m_dbm", b->n_beacons, b->rssi_1m_dbm);
    assert_true(b->site_rssi_1m_dbm == row("ble_rssi_1m_dbm")->v[0]);
    assert_true(b->path_loss_exponent == row("ble_path_loss_exponent")->v[0]);
    assert_true(b->range_sigma_db == row("ble_range_sigma_db")->v[0]);
    for (int i = 1; i < b->n_beacons; i++) {
        assert_true(b->id[i] > b->id[i - 1]); /* binary-searchable, as sf_radiomap.h promises */
    }
    sf_site_store_free(&store);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_v2_view),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
