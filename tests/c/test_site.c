/* test_site.c — sf_site_load / sf_site_parse against files written by the analyzer's Python writer
 * (tests/vectors/gen_site_vectors.py, run by CMake into SF_SITE_VECTORS_DIR):
 *   - round trip: every value of site.sfsite equals the writer's dump site.txt, in the core view and
 *     in the store, and ap_first matches an independent count;
 *   - every variant of variants.txt is rejected with the right code and the Python reader's message;
 *   - truncation at every length, every single-bit flip, an index made out of range (CRC recomputed
 *     here), missing file, directory, empty radio map encoded in C. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sf_error.h"
#include "sf_radiomap.h"
#include "sf_site.h"

#ifndef SF_SITE_VECTORS_DIR
#error "SF_SITE_VECTORS_DIR must name the directory gen_site_vectors.py wrote"
#endif

#define MAX_VALUES 64

typedef struct {
    char name[256];
    char source[256];
    double map_rotation_deg, origin_lat_deg, origin_lon_deg, cell_size_m;
    int has_geo, lowest_floor, has_fix_model;
    double fix_floor_cov_m2[3], fix_cov_per_acc2[3], fix_bias_sigma_m, fix_bias_length_m, fix_white_share;
    int n_floors, n_ap, n_rp, n_entries;
    double floor_height_m[MAX_VALUES];
    long long ap_bssid[MAX_VALUES];
    double rp_x_m[MAX_VALUES], rp_y_m[MAX_VALUES];
    long long rp_floor[MAX_VALUES], rp_scans[MAX_VALUES];
    long long entry_ap[MAX_VALUES], entry_rp[MAX_VALUES], entry_count[MAX_VALUES];
    double entry_mean_dbm[MAX_VALUES], entry_std_db[MAX_VALUES];
} dump_t;

static uint8_t *read_all(const char *const path, size_t *const size)
{
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        fail_msg("cannot open %s", path);
    }
    uint8_t *buf = malloc(1 << 20);
    assert_non_null(buf);
    *size = fread(buf, 1, 1 << 20, f);
    fclose(f);
    return buf;
}

static char *write_temp(const uint8_t *const data, const size_t size)
{
    static char path[64];
    strcpy(path, "/tmp/sf_test_site_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, data, size), (ssize_t)size);
    close(fd);
    return path;
}

static int parse_doubles(const char *s, double *const out)
{
    int n = 0;
    char *end = NULL;
    for (;;) {
        const double v = strtod(s, &end);
        if (end == s) {
            return n;
        }
        assert_true(n < MAX_VALUES);
        out[n++] = v;
        s = end;
    }
}

static int parse_ints(const char *s, long long *const out)
{
    int n = 0;
    char *end = NULL;
    for (;;) {
        const long long v = strtoll(s, &end, 10);
        if (end == s) {
            return n;
        }
        assert_true(n < MAX_VALUES);
        out[n++] = v;
        s = end;
    }
}

static void load_dump(dump_t *const d)
{
    memset(d, 0, sizeof *d);
    FILE *const f = fopen(SF_SITE_VECTORS_DIR "/site.txt", "r");
    assert_non_null(f);
    char line[4096];
    int fields = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        char *const sp = strchr(line, ' ');
        const char *const value = sp != NULL ? sp + 1 : "";
        if (sp != NULL) {
            *sp = '\0';
        }
        fields++;
        if (strcmp(line, "name") == 0) {
            snprintf(d->name, sizeof d->name, "%s", value);
        } else if (strcmp(line, "source") == 0) {
            snprintf(d->source, sizeof d->source, "%s", value);
        } else if (strcmp(line, "map_rotation_deg") == 0) {
            d->map_rotation_deg = strtod(value, NULL);
        } else if (strcmp(line, "has_geo") == 0) {
            d->has_geo = atoi(value);
        } else if (strcmp(line, "origin_lat_deg") == 0) {
            d->origin_lat_deg = strtod(value, NULL);
        } else if (strcmp(line, "origin_lon_deg") == 0) {
            d->origin_lon_deg = strtod(value, NULL);
        } else if (strcmp(line, "lowest_floor") == 0) {
            d->lowest_floor = atoi(value);
        } else if (strcmp(line, "cell_size_m") == 0) {
            d->cell_size_m = strtod(value, NULL);
        } else if (strcmp(line, "floor_height_m") == 0) {
            d->n_floors = parse_doubles(value, d->floor_height_m);
        } else if (strcmp(line, "ap_bssid") == 0) {
            d->n_ap = parse_ints(value, d->ap_bssid);
        } else if (strcmp(line, "rp_x_m") == 0) {
            d->n_rp = parse_doubles(value, d->rp_x_m);
        } else if (strcmp(line, "rp_y_m") == 0) {
            assert_int_equal(parse_doubles(value, d->rp_y_m), d->n_rp);
        } else if (strcmp(line, "rp_floor") == 0) {
            assert_int_equal(parse_ints(value, d->rp_floor), d->n_rp);
        } else if (strcmp(line, "rp_scans") == 0) {
            assert_int_equal(parse_ints(value, d->rp_scans), d->n_rp);
        } else if (strcmp(line, "entry_ap") == 0) {
            d->n_entries = parse_ints(value, d->entry_ap);
        } else if (strcmp(line, "entry_rp") == 0) {
            assert_int_equal(parse_ints(value, d->entry_rp), d->n_entries);
        } else if (strcmp(line, "entry_mean_dbm") == 0) {
            assert_int_equal(parse_doubles(value, d->entry_mean_dbm), d->n_entries);
        } else if (strcmp(line, "entry_std_db") == 0) {
            assert_int_equal(parse_doubles(value, d->entry_std_db), d->n_entries);
        } else if (strcmp(line, "entry_count") == 0) {
            assert_int_equal(parse_ints(value, d->entry_count), d->n_entries);
        } else if (strcmp(line, "has_fix_model") == 0) {
            d->has_fix_model = atoi(value);
        } else if (strcmp(line, "fix_bias_sigma_m") == 0) {
            d->fix_bias_sigma_m = strtod(value, NULL);
        } else if (strcmp(line, "fix_bias_length_m") == 0) {
            d->fix_bias_length_m = strtod(value, NULL);
        } else if (strcmp(line, "fix_white_share") == 0) {
            d->fix_white_share = strtod(value, NULL);
        } else if (strcmp(line, "fix_floor_cov_m2") == 0) {
            assert_int_equal(parse_doubles(value, d->fix_floor_cov_m2), 3);
        } else if (strcmp(line, "fix_cov_per_acc2") == 0) {
            assert_int_equal(parse_doubles(value, d->fix_cov_per_acc2), 3);
        } else {
            fail_msg("site.txt: unknown field '%s'", line);
        }
    }
    fclose(f);
    assert_int_equal(fields, 25); /* every field of site_t.lcm but the counts */
}

static void test_round_trip(void **state)
{
    (void)state;
    dump_t d;
    load_dump(&d);
    sf_site_store_t store;
    sf_site_t site;
    char err[512] = "";
    const int rc = sf_site_load(SF_SITE_VECTORS_DIR "/site.sfsite", &store, &site, err, sizeof err);
    if (rc != SF_OK) {
        fail_msg("load: %d %s", rc, err);
    }
    assert_string_equal(err, "");
    const stridefix_site_t *const m = &store.msg;
    assert_string_equal(m->name, d.name);
    assert_string_equal(m->source, d.source);
    assert_true(m->has_geo == d.has_geo);
    assert_true(m->origin_lat_deg == d.origin_lat_deg);
    assert_true(m->origin_lon_deg == d.origin_lon_deg);
    assert_true((double)m->cell_size_m == d.cell_size_m);
    assert_true(site.map_rotation_deg == d.map_rotation_deg);
    assert_true(site.fix_model.valid == (d.has_fix_model != 0));
    for (int i = 0; i < 3; i++) {
        assert_true(site.fix_model.cov_per_acc2[i] == d.fix_cov_per_acc2[i]);
        assert_true(site.fix_model.floor_cov_m2[i] == d.fix_floor_cov_m2[i]);
    }
    assert_true(site.fix_model.bias_sigma_m == d.fix_bias_sigma_m);
    assert_true(site.fix_model.bias_length_m == d.fix_bias_length_m);
    assert_true(site.fix_model.white_share == d.fix_white_share);
    assert_int_equal(site.lowest_floor, d.lowest_floor);
    assert_int_equal(site.n_floors, d.n_floors);
    for (int i = 0; i < d.n_floors; i++) {
        assert_true(site.floor_height_m[i] == d.floor_height_m[i]);
    }
    const sf_radiomap_t *const r = &site.radiomap;
    assert_int_equal(r->n_ap, d.n_ap);
    for (int a = 0; a < d.n_ap; a++) {
        assert_true(r->ap_bssid[a] == d.ap_bssid[a]);
        assert_int_equal(sf_radiomap_find_ap(r, r->ap_bssid[a]), a);
    }
    assert_int_equal(r->n_rp, d.n_rp);
    for (int i = 0; i < d.n_rp; i++) {
        assert_true((double)r->rp_x_m[i] == d.rp_x_m[i]);
        assert_true((double)r->rp_y_m[i] == d.rp_y_m[i]);
        assert_int_equal(r->rp_floor[i], d.rp_floor[i]);
        assert_int_equal(r->rp_scans[i], d.rp_scans[i]);
    }
    assert_int_equal(r->n_entries, d.n_entries);
    for (int i = 0; i < d.n_entries; i++) {
        assert_int_equal(m->entry_ap[i], d.entry_ap[i]);
        assert_int_equal(r->entry_rp[i], d.entry_rp[i]);
        assert_true((double)r->entry_mean_dbm[i] == d.entry_mean_dbm[i]);
        assert_true((double)r->entry_std_db[i] == d.entry_std_db[i]);
        assert_int_equal(r->entry_count[i], d.entry_count[i]);
    }
    /* ap_first from an independent count: entries of AP a are ap_first[a] .. ap_first[a+1]−1 */
    int first = 0;
    for (int a = 0; a < d.n_ap; a++) {
        assert_int_equal(r->ap_first[a], first);
        for (int i = 0; i < d.n_entries; i++) {
            first += d.entry_ap[i] == a;
        }
        for (int i = r->ap_first[a]; i < first; i++) {
            assert_int_equal(m->entry_ap[i], a);
        }
    }
    assert_int_equal(r->ap_first[d.n_ap], d.n_entries);
    assert_int_equal(r->ap_first[2], r->ap_first[3]); /* AP 2 has no entry in the vector site */
    assert_int_equal(sf_radiomap_check(r, NULL), SF_OK);
    sf_site_store_free(&store);
    assert_null(store.ap_first);
    assert_int_equal(store.loaded, 0);
    sf_site_store_free(&store); /* idempotent */
}

static void test_crc32_reference(void **state)
{
    (void)state;
    assert_int_equal(sf_site_crc32("123456789", 9), 0xCBF43926u); /* the CRC-32/IEEE check value */
    assert_int_equal(sf_site_crc32("", 0), 0u);
    size_t size = 0;
    uint8_t *const buf = read_all(SF_SITE_VECTORS_DIR "/site.sfsite", &size);
    const uint32_t header_crc = (uint32_t)buf[16] | ((uint32_t)buf[17] << 8) | ((uint32_t)buf[18] << 16) |
                                ((uint32_t)buf[19] << 24);
    assert_int_equal(sf_site_crc32(buf + SF_SITE_HEADER_SIZE, size - SF_SITE_HEADER_SIZE), header_crc); /* = zlib */
    free(buf);
    /* slicing-by-8 against the bytewise definition at every length and alignment up to 64 bytes */
    uint8_t bytes[72];
    for (size_t i = 0; i < sizeof bytes; i++) {
        bytes[i] = (uint8_t)(i * 37u + 11u);
    }
    for (size_t off = 0; off < 8; off++) {
        for (size_t n = 0; n <= 64; n++) {
            uint32_t crc = 0xFFFFFFFFu;
            for (size_t i = 0; i < n; i++) {
                crc ^= bytes[off + i];
                for (int k = 0; k < 8; k++) {
                    crc = (crc & 1u) != 0u ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
                }
            }
            assert_int_equal(sf_site_crc32(bytes + off, n), crc ^ 0xFFFFFFFFu);
        }
    }
}

/* Every variant of variants.txt: code from its kind, message "<path>: <text>" (exact or contained). */
static void test_python_variants_rejected(void **state)
{
    (void)state;
    FILE *const f = fopen(SF_SITE_VECTORS_DIR "/variants.txt", "r");
    assert_non_null(f);
    char line[1024];
    int n = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        char *const name = strtok(line, "\t");
        char *const kind = strtok(NULL, "\t");
        char *const match = strtok(NULL, "\t");
        char *const text = strtok(NULL, "");
        assert_non_null(text);
        char path[512];
        snprintf(path, sizeof path, "%s/variants/%s.sfsite", SF_SITE_VECTORS_DIR, name);
        sf_site_store_t store;
        sf_site_t site;
        char err[1024] = "";
        const int rc = sf_site_load(path, &store, &site, err, sizeof err);
        const int want = strcmp(kind, "field") == 0 ? SF_ERANGE : SF_ESYNTAX;
        if (rc != want) {
            fail_msg("variant %s: got %d (%s), want %d; message: %s", name, rc, sf_strerror(rc), want, err);
        }
        char expected[1024];
        snprintf(expected, sizeof expected, "%s: %s", path, text);
        if (strcmp(match, "exact") == 0 ? strcmp(err, expected) != 0 : strstr(err, text) == NULL) {
            fail_msg("variant %s (%s):\n  got  '%s'\n  want '%s'", name, match, err, expected);
        }
        assert_int_equal(store.loaded, 0); /* a failed load leaves nothing to free */
        assert_null(store.ap_first);
        assert_int_equal(site.radiomap.n_entries, 0);
        n++;
    }
    fclose(f);
    assert_true(n >= 80); /* the header, v1, v2 and v3 variants */
}

static void test_truncation_at_every_length(void **state)
{
    (void)state;
    size_t size = 0;
    uint8_t *const buf = read_all(SF_SITE_VECTORS_DIR "/site.sfsite", &size);
    assert_true(size > SF_SITE_HEADER_SIZE && size < 1000);
    for (size_t n = 0; n < size; n++) {
        uint8_t *const part = malloc(n > 0 ? n : 1); /* exactly n bytes so ASan/valgrind see overreads */
        assert_non_null(part);
        memcpy(part, buf, n);
        sf_site_store_t store;
        sf_site_t site;
        char err[512] = "";
        const int rc = sf_site_parse(part, n, "cut.sfsite", &store, &site, err, sizeof err);
        if (rc != SF_ESYNTAX) {
            fail_msg("cut at %zu of %zu: got %d, message %s", n, size, rc, err);
        }
        const char *const needle = n < SF_SITE_HEADER_SIZE ? "a site file starts with a 24-byte header"
                                                           : "length mismatch (truncated): header says";
        if (strncmp(err, "cut.sfsite: ", 12) != 0 || strstr(err, needle) == NULL) {
            fail_msg("cut at %zu: message '%s' lacks '%s'", n, err, needle);
        }
        free(part);
    }
    /* the same through a real file at a few lengths */
    const size_t cuts[] = {0, 7, SF_SITE_HEADER_SIZE, size - 1};
    for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
        const char *const path = write_temp(buf, cuts[k]);
        sf_site_store_t store;
        sf_site_t site;
        char err[512];
        assert_int_equal(sf_site_load(path, &store, &site, err, sizeof err), SF_ESYNTAX);
        assert_true(strncmp(err, path, strlen(path)) == 0);
        unlink(path);
    }
    free(buf);
}

/* Any single-bit flip anywhere is caught (header fields by their own checks, payload by the CRC). */
static void test_every_bit_flip_rejected(void **state)
{
    (void)state;
    size_t size = 0;
    uint8_t *const buf = read_all(SF_SITE_VECTORS_DIR "/site.sfsite", &size);
    for (size_t i = 0; i < size; i++) {
        for (int bit = 0; bit < 8; bit++) {
            buf[i] ^= (uint8_t)(1u << bit);
            sf_site_store_t store;
            sf_site_t site;
            char err[512];
            const int rc = sf_site_parse(buf, size, "flip.sfsite", &store, &site, err, sizeof err);
            if (rc != SF_ESYNTAX) {
                fail_msg("flip byte %zu bit %d: got %d (%s)", i, bit, rc, err);
            }
            if (i >= SF_SITE_HEADER_SIZE && strstr(err, "CRC-32 mismatch: header says 0x") == NULL) {
                fail_msg("flip payload byte %zu: '%s' is not a CRC error", i, err);
            }
            buf[i] ^= (uint8_t)(1u << bit);
        }
    }
    free(buf);
}

static void put_be32(uint8_t *const p, const int32_t v)
{
    const uint32_t u = (uint32_t)v;
    p[0] = (uint8_t)(u >> 24);
    p[1] = (uint8_t)(u >> 16);
    p[2] = (uint8_t)(u >> 8);
    p[3] = (uint8_t)u;
}

static void put_le32(uint8_t *const p, const uint32_t u)
{
    p[0] = (uint8_t)u;
    p[1] = (uint8_t)(u >> 8);
    p[2] = (uint8_t)(u >> 16);
    p[3] = (uint8_t)(u >> 24);
}

/* entry_rp[2] := 300 with the CRC recomputed here: only the field check can catch it. */
static void test_index_out_of_range(void **state)
{
    (void)state;
    dump_t d;
    load_dump(&d);
    size_t size = 0;
    uint8_t *const buf = read_all(SF_SITE_VECTORS_DIR "/site.sfsite", &size);
    /* the payload has the five entry arrays of n_entries int32/float each (rp is the second), then
     * the fix model: has_fix_model (1 B) and nine floats, then the version-2 and version-3 fields
     * (their sizes from the file as loaded) */
    sf_site_store_t loaded;
    sf_site_t view;
    assert_int_equal(sf_site_parse(buf, size, "site.sfsite", &loaded, &view, NULL, 0), SF_OK);
    const size_t v2_bytes = 8u + 8u + 4u + 18u * (size_t)loaded.msg.n_walls + 4u + 18u * (size_t)loaded.msg.n_ports +
                            4u + 22u * (size_t)loaded.msg.n_beacons + 3u * 4u;
    /* the version-3 fields: names (int32 length, bytes, NUL each), outline, per-port extras, links,
     * contexts, constellation members */
    size_t v3_bytes = 4u + 4u + 10u * (size_t)loaded.msg.n_outline + 22u * (size_t)loaded.msg.n_ports + 4u +
                      8u * (size_t)loaded.msg.n_links + 4u + 14u * (size_t)loaded.msg.n_contexts + 4u +
                      14u * (size_t)loaded.msg.n_cdd;
    for (int32_t b = 0; b < loaded.msg.n_buildings; b++) {
        v3_bytes += 4u + strlen(loaded.msg.building_name[b]) + 1u;
    }
    assert_true(loaded.msg.n_contexts > 0); /* the vector site has a context map */
    sf_site_store_free(&loaded);
    const size_t fix_model_bytes = 1u + 9u * 4u;
    const size_t entry_rp_at = size - v3_bytes - v2_bytes - fix_model_bytes - 4u * (size_t)d.n_entries * 4u;
    put_be32(buf + entry_rp_at + 4u * 2u, 300);
    put_le32(buf + 16, sf_site_crc32(buf + SF_SITE_HEADER_SIZE, size - SF_SITE_HEADER_SIZE));
    sf_site_store_t store;
    sf_site_t site;
    char err[512];
    assert_int_equal(sf_site_parse(buf, size, "site.sfsite", &store, &site, err, sizeof err), SF_ERANGE);
    char want[128];
    snprintf(want, sizeof want, "site.sfsite: entry 2: rp index 300 outside 0..%d", d.n_rp - 1);
    assert_string_equal(err, want);
    free(buf);
}

static void test_missing_file_and_directory(void **state)
{
    (void)state;
    sf_site_store_t store;
    sf_site_t site;
    char err[512];
    assert_int_equal(sf_site_load("/nonexistent/dir/site.sfsite", &store, &site, err, sizeof err), SF_ENOENT);
    assert_non_null(strstr(err, "/nonexistent/dir/site.sfsite: cannot open site file: "));
    assert_int_equal(sf_site_load("/tmp", &store, &site, err, sizeof err), SF_EIO);
    assert_true(strncmp(err, "/tmp: ", 6) == 0);
    assert_int_equal(sf_site_load(NULL, &store, &site, err, sizeof err), SF_EINVAL);
    assert_int_equal(sf_site_load("x", NULL, &site, err, sizeof err), SF_EINVAL);
    assert_int_equal(sf_site_load("x", &store, &site, NULL, 0), SF_ENOENT); /* no message buffer: fine */
}

/* A site with floors only (no radio map), encoded by the generated C encoder: loads, n_rp = 0. */
static void test_empty_radiomap_from_c_encoder(void **state)
{
    (void)state;
    double heights[2] = {0.0, 3.5};
    stridefix_site_t m;
    memset(&m, 0, sizeof m);
    m.name = "empty";
    m.source = "test_site.c";
    m.map_rotation_deg = -30.0;
    m.lowest_floor = 0;
    m.n_floors = 2;
    m.floor_height_m = heights;
    const int payload_size = stridefix_site_t_encoded_size(&m);
    uint8_t *const buf = calloc(1, (size_t)SF_SITE_HEADER_SIZE + (size_t)payload_size);
    assert_non_null(buf);
    assert_int_equal(stridefix_site_t_encode(buf + SF_SITE_HEADER_SIZE, 0, payload_size, &m), payload_size);
    memcpy(buf, "SFSITE\0\x01", 8);
    put_le32(buf + 8, SF_SITE_FORMAT_VERSION);
    put_le32(buf + 12, (uint32_t)payload_size);
    put_le32(buf + 16, sf_site_crc32(buf + SF_SITE_HEADER_SIZE, (size_t)payload_size));
    sf_site_store_t store;
    sf_site_t site;
    char err[512] = "";
    const int rc = sf_site_parse(buf, (size_t)SF_SITE_HEADER_SIZE + (size_t)payload_size, "empty.sfsite", &store,
                                 &site, err, sizeof err);
    if (rc != SF_OK) {
        fail_msg("%d: %s", rc, err);
    }
    assert_int_equal(site.radiomap.n_rp, 0);
    assert_int_equal(site.radiomap.n_ap, 0);
    assert_int_equal(site.n_floors, 2);
    assert_true(site.floor_height_m[1] == 3.5);
    assert_true(site.map_rotation_deg == -30.0);
    assert_int_equal(site.radiomap.ap_first[0], 0);
    assert_int_equal(sf_radiomap_find_ap(&site.radiomap, 42), -1);
    assert_string_equal(store.msg.name, "empty");
    assert_false(site.geo.valid); /* no version-2 content: every view empty */
    assert_int_equal(site.plan.n_walls, 0);
    assert_int_equal(site.ports.n_ports, 0);
    assert_int_equal(site.beacons.n_beacons, 0);
    assert_int_equal(site.contexts.n_contexts, 0); /* no version-3 content: no controller */
    assert_int_equal(site.contexts.n_buildings, 0);
    sf_site_store_free(&store);
    free(buf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_crc32_reference),
        cmocka_unit_test(test_python_variants_rejected),
        cmocka_unit_test(test_truncation_at_every_length),
        cmocka_unit_test(test_every_bit_flip_rejected),
        cmocka_unit_test(test_index_out_of_range),
        cmocka_unit_test(test_missing_file_and_directory),
        cmocka_unit_test(test_empty_radiomap_from_c_encoder),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
