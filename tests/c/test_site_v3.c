/* test_site_v3.c — the version-3 content of a site file (the multi-scheme controller's context map:
 * buildings and outlines, per-port extras, links, contexts, constellations) reaches the core view
 * (sf_site_t.contexts) with every value the analyzer's writer put there (tests/vectors/
 * gen_site_vectors.py: site.sfsite and its dump site_v3.txt); a site encoded here in C with a
 * staircase and the neutral per-port extras loads without a context map and is refused with one (the
 * stairs rule needs the step count). The rules' rejections are test_site.c's variants. */
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
#include "sf_types.h"

#ifndef SF_SITE_VECTORS_DIR
#error "SF_SITE_VECTORS_DIR must name the directory gen_site_vectors.py wrote"
#endif

#define MAX_VALUES 32
#define MAX_ROWS 32

typedef struct {
    const char *name;
    const char *text; /* the values as written */
    int n;
    double v[MAX_VALUES];
} row_t;

static row_t rows[MAX_ROWS];
static int n_rows;

static void load_rows(void)
{
    n_rows = 0;
    FILE *const f = fopen(SF_SITE_VECTORS_DIR "/site_v3.txt", "r");
    assert_non_null(f);
    static char lines[MAX_ROWS][1024];
    while (n_rows < MAX_ROWS && fgets(lines[n_rows], sizeof lines[0], f) != NULL) {
        char *const line = lines[n_rows];
        line[strcspn(line, "\n")] = '\0';
        char *sp = strchr(line, ' ');
        row_t *const r = &rows[n_rows++];
        r->name = line;
        r->text = "";
        r->n = 0;
        if (sp == NULL) {
            continue;
        }
        *sp = '\0';
        r->text = sp + 1;
        const char *s = sp + 1;
        for (;;) {
            char *end = NULL;
            const double v = strtod(s, &end); /* ids < 2^53 are exact doubles */
            if (end == s) {
                break;
            }
            assert_true(r->n < MAX_VALUES);
            r->v[r->n++] = v;
            s = end;
        }
    }
    fclose(f);
    assert_int_equal(n_rows, 23); /* the 23 arrays of site_t.lcm's version-3 fields */
}

static const row_t *row(const char *const name)
{
    for (int i = 0; i < n_rows; i++) {
        if (strcmp(rows[i].name, name) == 0) {
            return &rows[i];
        }
    }
    fail_msg("site_v3.txt has no %s", name);
    return NULL;
}

#define EXPECT_ARRAY(field, count, array)                                                                   \
    do {                                                                                                    \
        const row_t *const r_ = row(field);                                                                 \
        assert_int_equal(r_->n, (count));                                                                   \
        for (int i_ = 0; i_ < r_->n; i_++) {                                                                \
            if (!((double)(array)[i_] == r_->v[i_])) {                                                      \
                fail_msg("%s[%d] = %g, file says %g", field, i_, (double)(array)[i_], r_->v[i_]);           \
            }                                                                                               \
        }                                                                                                   \
    } while (0)

static void test_v3_view(void **state)
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
    const sf_context_map_t *const c = &site.contexts;
    /* building names: the dump's space-separated list */
    char names[256] = "";
    for (int32_t b = 0; b < store.msg.n_buildings; b++) {
        strncat(names, b > 0 ? " " : "", sizeof names - strlen(names) - 1);
        strncat(names, store.msg.building_name[b], sizeof names - strlen(names) - 1);
    }
    assert_string_equal(names, row("building_name")->text);
    assert_int_equal(c->n_buildings, store.msg.n_buildings);
    assert_true(c->n_outline > 0);
    EXPECT_ARRAY("outline_x_m", c->n_outline, c->outline_x_m);
    EXPECT_ARRAY("outline_y_m", c->n_outline, c->outline_y_m);
    EXPECT_ARRAY("outline_building", c->n_outline, c->outline_building);
    const int32_t np = site.ports.n_ports;
    assert_true(np > 0);
    EXPECT_ARRAY("port_building", np, c->port_building);
    EXPECT_ARRAY("port_outdoor", np, c->port_outdoor);
    EXPECT_ARRAY("port_steps", np, c->port_steps);
    EXPECT_ARRAY("port_lo_x_m", np, c->port_lo_x_m);
    EXPECT_ARRAY("port_lo_y_m", np, c->port_lo_y_m);
    EXPECT_ARRAY("port_hi_x_m", np, c->port_hi_x_m);
    EXPECT_ARRAY("port_hi_y_m", np, c->port_hi_y_m);
    assert_true(c->n_links > 0);
    EXPECT_ARRAY("link_a", c->n_links, c->link_a);
    EXPECT_ARRAY("link_b", c->n_links, c->link_b);
    assert_true(c->n_contexts >= 3);
    EXPECT_ARRAY("context_kind", c->n_contexts, c->kind);
    EXPECT_ARRAY("context_building", c->n_contexts, c->building);
    EXPECT_ARRAY("context_floor", c->n_contexts, c->floor);
    EXPECT_ARRAY("context_scheme", c->n_contexts, c->scheme);
    EXPECT_ARRAY("context_method", c->n_contexts, c->method);
    EXPECT_ARRAY("context_cdd_method", c->n_contexts, c->cdd_method);
    EXPECT_ARRAY("context_cdd_min_hits", c->n_contexts, c->cdd_min_hits);
    assert_true(c->n_cdd > 0);
    EXPECT_ARRAY("cdd_context", c->n_cdd, c->cdd_context);
    EXPECT_ARRAY("cdd_id", c->n_cdd, c->cdd_id);
    EXPECT_ARRAY("cdd_min_dbm", c->n_cdd, c->cdd_min_dbm);
    for (int32_t i = 0; i < c->n_contexts; i++) {
        assert_true(c->scheme[i] >= 0 && c->scheme[i] < (int16_t)sf_scheme_count); /* never the controller */
    }
    sf_site_store_free(&store);
}

static void put_le32(uint8_t *const p, const uint32_t u)
{
    p[0] = (uint8_t)u;
    p[1] = (uint8_t)(u >> 8);
    p[2] = (uint8_t)(u >> 16);
    p[3] = (uint8_t)(u >> 24);
}

/* A two-floor site with one staircase, encoded by the generated C encoder with the neutral per-port
 * extras (no building, not outdoor, 0 steps, endpoints at the centre) and, when with_context, one
 * floor context: parse it and return the code (err gets the message). */
static int parse_c_site(const int with_context, char *const err, const size_t err_size, sf_site_t *const out)
{
    double heights[2] = {0.0, 3.5};
    int16_t kind[1] = {sf_port_stairs}, lo[1] = {0}, hi[1] = {1}, none[1] = {-1}, zero[1] = {0};
    float x[1] = {4.0f}, y[1] = {2.0f}, r[1] = {1.5f};
    char *names[1] = {"A"};
    float ox[3] = {0.0f, 10.0f, 0.0f}, oy[3] = {0.0f, 0.0f, 10.0f};
    int16_t ob[3] = {0, 0, 0};
    int16_t ck[1] = {sf_context_floor}, cb[1] = {0}, cf[1] = {0}, cs[1] = {sf_scheme_ekf};
    int16_t cm[1] = {sf_fix_wifi}, ch[1] = {1};
    stridefix_site_t m;
    memset(&m, 0, sizeof m);
    m.name = "c-encoded";
    m.source = "test_site_v3.c";
    m.n_floors = 2;
    m.floor_height_m = heights;
    m.n_ports = 1;
    m.port_kind = kind;
    m.port_x_m = x;
    m.port_y_m = y;
    m.port_radius_m = r;
    m.port_floor_lo = lo;
    m.port_floor_hi = hi;
    m.port_building = none;
    m.port_outdoor = zero;
    m.port_steps = zero;
    m.port_lo_x_m = x;
    m.port_lo_y_m = y;
    m.port_hi_x_m = x;
    m.port_hi_y_m = y;
    if (with_context) {
        m.n_buildings = 1;
        m.building_name = names;
        m.n_outline = 3;
        m.outline_x_m = ox;
        m.outline_y_m = oy;
        m.outline_building = ob;
        m.n_contexts = 1;
        m.context_kind = ck;
        m.context_building = cb;
        m.context_floor = cf;
        m.context_scheme = cs;
        m.context_method = cm;
        m.context_cdd_method = cm;
        m.context_cdd_min_hits = ch;
    }
    const int payload_size = stridefix_site_t_encoded_size(&m);
    uint8_t *const buf = calloc(1, (size_t)SF_SITE_HEADER_SIZE + (size_t)payload_size);
    assert_non_null(buf);
    assert_int_equal(stridefix_site_t_encode(buf + SF_SITE_HEADER_SIZE, 0, payload_size, &m), payload_size);
    memcpy(buf, "SFSITE\0\x01", 8);
    put_le32(buf + 8, SF_SITE_FORMAT_VERSION);
    put_le32(buf + 12, (uint32_t)payload_size);
    put_le32(buf + 16, sf_site_crc32(buf + SF_SITE_HEADER_SIZE, (size_t)payload_size));
    sf_site_store_t store;
    const int rc = sf_site_parse(buf, (size_t)SF_SITE_HEADER_SIZE + (size_t)payload_size, "c.sfsite", &store, out,
                                 err, err_size);
    if (rc == SF_OK) {
        assert_int_equal(out->ports.n_ports, 1);
        assert_int_equal(out->contexts.port_steps[0], 0);
        assert_int_equal(out->contexts.port_building[0], -1);
        assert_true(out->contexts.port_lo_x_m[0] == 4.0f && out->contexts.port_hi_y_m[0] == 2.0f);
        assert_int_equal(out->contexts.n_contexts, 0);
    }
    sf_site_store_free(&store);
    free(buf);
    return rc;
}

static void test_c_encoded_stairs_without_and_with_contexts(void **state)
{
    (void)state;
    char err[512] = "";
    sf_site_t site;
    int rc = parse_c_site(0, err, sizeof err, &site);
    if (rc != SF_OK) {
        fail_msg("without contexts: %d %s", rc, err);
    }
    rc = parse_c_site(1, err, sizeof err, &site);
    assert_int_equal(rc, SF_ERANGE);
    assert_string_equal(err, "c.sfsite: port 0: stairs with port_steps 0 (a staircase needs its step count when "
                             "the site has contexts)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_v3_view),
        cmocka_unit_test(test_c_encoded_stairs_without_and_with_contexts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
