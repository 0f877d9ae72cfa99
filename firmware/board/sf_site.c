/* sf_site.c — site file → sf_site_t (see sf_site.h for the format, the checks and the ownership). */
#include "sf_site.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_cls.h"
#include "sf_error.h"
#include "sf_file_kind.h"
#include "sf_lcm_walk.h"
#include "sf_site_ranges.h"
#include "sf_site_v2.h"
#include "sf_site_v3.h"

static const uint8_t magic[8] = {'S', 'F', 'S', 'I', 'T', 'E', 0u, 1u};

/* Slicing-by-8 (Kounavis & Berry 2005): eight bytes per step through eight tables, each table k the
 * CRC of a byte followed by k zero bytes; the same CRC as the bytewise loop, ~3x fewer instructions
 * (a replay reads a 1.5 MB site: the CRC was a fifth of its instructions). */
uint32_t sf_site_crc32(const void *const data, const size_t n)
{
    uint32_t t[8][256]; /* built per call (~10 k operations): no global state, small next to a site */
    for (uint32_t i = 0; i < 256u; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++) {
            c = (c & 1u) != 0u ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        }
        t[0][i] = c;
    }
    for (uint32_t i = 0; i < 256u; i++) {
        for (int k = 1; k < 8; k++) {
            t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
        }
    }
    const uint8_t *p = data;
    size_t left = n;
    uint32_t crc = 0xFFFFFFFFu;
    for (; left >= 8u; left -= 8u, p += 8) {
        const uint32_t lo = crc ^ ((uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24));
        const uint32_t hi = (uint32_t)p[4] | ((uint32_t)p[5] << 8) | ((uint32_t)p[6] << 16) | ((uint32_t)p[7] << 24);
        crc = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
              t[3][hi & 0xFFu] ^ t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
    }
    for (; left > 0u; left--, p++) {
        crc = t[0][(crc ^ *p) & 0xFFu] ^ (crc >> 8);
    }
    return crc ^ 0xFFFFFFFFu;
}

static uint32_t le32(const uint8_t *const p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* --- payload bounds walk (sf_lcm_walk.h says why: the generated decoder trusts the counts) ------- */

static int walk_site(sf_lcm_walk_t *const w)
{
    int rc = sf_lcm_walk_skip(w, 8, "type hash");
    rc = rc != SF_OK ? rc : sf_lcm_walk_string(w, "name");
    rc = rc != SF_OK ? rc : sf_lcm_walk_string(w, "source");
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(w, 8 + 1 + 8 + 8 + 2, "map_rotation_deg .. lowest_floor");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_floors", 8);
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_ap", 8);
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(w, 4, "cell_size_m");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_rp", 4 + 4 + 2 + 4);
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(w, "n_entries", 4 + 4 + 4 + 4 + 4);
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(w, 1 + 3 * 4 + 3 * 4 + 3 * 4, "has_fix_model .. fix_white_share");
    int32_t n_ports = 0;
    rc = rc != SF_OK ? rc : sf_site_v2_walk(w, &n_ports);
    rc = rc != SF_OK ? rc : sf_site_v3_walk(w, n_ports);
    return rc != SF_OK ? rc : sf_lcm_walk_end(w, "site_t");
}

/* --- field rules (the same order and words as sitefile.validate_site) -------------------------- */

static int check_fields(const stridefix_site_t *const s, const char *const name, char *const err,
                        const size_t err_size)
{
#define BAD(...) sf_lcm_failf(err, err_size, name, SF_ERANGE, __VA_ARGS__)
    if (!isfinite(s->map_rotation_deg)) {
        return BAD("map_rotation_deg is %g, must be finite", s->map_rotation_deg);
    }
    if (s->has_geo) {
        if (!(isfinite(s->origin_lat_deg) && s->origin_lat_deg >= -90.0 && s->origin_lat_deg <= 90.0)) {
            return BAD("origin_lat_deg = %g outside -90..90", s->origin_lat_deg);
        }
        if (!(isfinite(s->origin_lon_deg) && s->origin_lon_deg >= -180.0 && s->origin_lon_deg <= 180.0)) {
            return BAD("origin_lon_deg = %g outside -180..180", s->origin_lon_deg);
        }
        const int geo_rc = sf_site_v2_check_geo(s, name, err, err_size);
        if (geo_rc != SF_OK) {
            return geo_rc;
        }
    }
    if (s->has_fix_model) {
        const double fxx = s->fix_floor_cov_m2[0], fxy = s->fix_floor_cov_m2[1], fyy = s->fix_floor_cov_m2[2];
        if (!(isfinite(fxx) && isfinite(fxy) && isfinite(fyy) && fxx >= 0.0 && fyy >= 0.0 && fxx * fyy >= fxy * fxy)) {
            return BAD("fix_floor_cov_m2 = [%g, %g, %g] not positive semi-definite", fxx, fxy, fyy);
        }
        const double xx = s->fix_cov_per_acc2[0], xy = s->fix_cov_per_acc2[1], yy = s->fix_cov_per_acc2[2];
        if (!(isfinite(xx) && isfinite(xy) && isfinite(yy) && xx > 0.0 && yy > 0.0 && xx * yy > xy * xy)) {
            return BAD("fix_cov_per_acc2 = [%g, %g, %g] not positive definite", xx, xy, yy);
        }
        if (!(isfinite(s->fix_bias_sigma_m) && s->fix_bias_sigma_m >= 0.0f)) {
            return BAD("fix_bias_sigma_m = %g, must be finite and >= 0", (double)s->fix_bias_sigma_m);
        }
        if (!(isfinite(s->fix_bias_length_m) && s->fix_bias_length_m > 0.0f)) {
            return BAD("fix_bias_length_m = %g, must be finite and > 0", (double)s->fix_bias_length_m);
        }
        if (!(isfinite(s->fix_white_share) && s->fix_white_share >= 0.0f && s->fix_white_share <= 1.0f)) {
            return BAD("fix_white_share = %g outside 0..1", (double)s->fix_white_share);
        }
    }
    if (s->n_floors < 1) {
        return BAD("n_floors = 0: a site has at least one floor");
    }
    const int32_t lowest = s->lowest_floor;
    const int32_t top = lowest + s->n_floors - 1;
    if (top > 32767) {
        return BAD("floors %d..%d overflow int16", (int)lowest, (int)top);
    }
    for (int32_t i = 0; i < s->n_floors; i++) {
        const double h = s->floor_height_m[i];
        if (!isfinite(h)) {
            return BAD("floor_height_m[%d] is %g, must be finite", (int)i, h);
        }
        if (i > 0 && !(h > s->floor_height_m[i - 1])) {
            return BAD("floor_height_m[%d] = %g not above floor_height_m[%d] = %g (heights must increase)", (int)i,
                       h, (int)(i - 1), s->floor_height_m[i - 1]);
        }
    }
    for (int32_t a = 0; a < s->n_ap; a++) {
        const int64_t b = s->ap_bssid[a];
        if (b < 0 || b >= ((int64_t)1 << 48)) {
            return BAD("ap %d: BSSID %lld outside 0..2^48-1", (int)a, (long long)b);
        }
        if (a > 0 && !(b > s->ap_bssid[a - 1])) {
            return BAD("ap %d: BSSID 0x%012llx not above ap %d's 0x%012llx (BSSIDs must be strictly ascending)",
                       (int)a, (unsigned long long)b, (int)(a - 1), (unsigned long long)s->ap_bssid[a - 1]);
        }
    }
    if (!(isfinite(s->cell_size_m) && s->cell_size_m >= 0.0f)) {
        return BAD("cell_size_m = %g, must be finite and >= 0", (double)s->cell_size_m);
    }
    for (int32_t r = 0; r < s->n_rp; r++) {
        const float x = s->rp_x_m[r];
        const float y = s->rp_y_m[r];
        if (!(isfinite(x) && isfinite(y))) {
            return BAD("rp %d: position (%g, %g) not finite", (int)r, (double)x, (double)y);
        }
        if (s->rp_floor[r] < lowest || s->rp_floor[r] > top) {
            return BAD("rp %d: floor %d outside %d..%d", (int)r, (int)s->rp_floor[r], (int)lowest, (int)top);
        }
        if (s->rp_scans[r] < 1) {
            return BAD("rp %d: rp_scans = %d, must be >= 1", (int)r, (int)s->rp_scans[r]);
        }
    }
    for (int32_t i = 0; i < s->n_entries; i++) {
        const int32_t a = s->entry_ap[i];
        const int32_t r = s->entry_rp[i];
        if (a < 0 || a >= s->n_ap) {
            return BAD("entry %d: ap index %d outside 0..%d", (int)i, (int)a, (int)(s->n_ap - 1));
        }
        if (r < 0 || r >= s->n_rp) {
            return BAD("entry %d: rp index %d outside 0..%d", (int)i, (int)r, (int)(s->n_rp - 1));
        }
        if (i > 0) {
            const int32_t pa = s->entry_ap[i - 1];
            const int32_t pr = s->entry_rp[i - 1];
            if (!(a > pa || (a == pa && r > pr))) {
                return BAD("entry %d: (ap %d, rp %d) not after entry %d's (ap %d, rp %d) (entries must be sorted "
                           "by (ap, rp), no duplicates)",
                           (int)i, (int)a, (int)r, (int)(i - 1), (int)pa, (int)pr);
            }
        }
        const float mean = s->entry_mean_dbm[i];
        const float std = s->entry_std_db[i];
        const int32_t count = s->entry_count[i];
        if (!isfinite(mean)) {
            return BAD("entry %d: entry_mean_dbm is %g, must be finite", (int)i, (double)mean);
        }
        if (!(isfinite(std) && std >= 0.0f)) {
            return BAD("entry %d: entry_std_db = %g, must be finite and >= 0", (int)i, (double)std);
        }
        if (count < 1 || count > s->rp_scans[r]) {
            return BAD("entry %d: count %d outside 1..%d (rp_scans of rp %d)", (int)i, (int)count,
                       (int)s->rp_scans[r], (int)r);
        }
    }
    int rc = sf_site_v2_check_plan(s, (int)lowest, (int)top, name, err, err_size);
    rc = rc != SF_OK ? rc : sf_site_v3_check(s, (int)lowest, (int)top, name, err, err_size);
    return rc != SF_OK ? rc : sf_site_check_ranges(s, name, err, err_size);
#undef BAD
}

/* --- loading -------------------------------------------------------------------------------------- */

void sf_site_store_free(sf_site_store_t *const store)
{
    if (store == NULL) {
        return;
    }
    if (store->loaded) {
        stridefix_site_t_decode_cleanup(&store->msg);
    }
    free(store->ap_first);
    memset(store, 0, sizeof *store);
}

static int check_header(const uint8_t *const data, const size_t size, const char *const name, char *const err,
                        const size_t err_size)
{
    if (size < SF_SITE_HEADER_SIZE) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX,
                            "file has only %zu bytes; a site file starts with a %d-byte header", size,
                            SF_SITE_HEADER_SIZE);
    }
    if (memcmp(data, magic, sizeof magic) != 0) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX,
                            "bad magic %02x %02x %02x %02x %02x %02x %02x %02x, expected 53 46 53 49 54 45 00 01 "
                            "(not a StrideFix site file)",
                            data[0], data[1], data[2], data[3], data[4], data[5], data[6], data[7]);
    }
    const uint32_t version = le32(data + 8);
    const uint32_t length = le32(data + 12);
    const uint32_t crc = le32(data + 16);
    const uint32_t reserved = le32(data + 20);
    if (version == 1u || version == 2u) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX,
                            "format version %lu, this build reads %u: rebuild it with `stridefix radiomap build`",
                            (unsigned long)version, SF_SITE_FORMAT_VERSION);
    }
    if (version != SF_SITE_FORMAT_VERSION) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX, "format version %lu, this reader supports %u",
                            (unsigned long)version, SF_SITE_FORMAT_VERSION);
    }
    if (reserved != 0u) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX, "reserved header field is 0x%08lx, must be 0",
                            (unsigned long)reserved);
    }
    const size_t have = size - SF_SITE_HEADER_SIZE;
    if ((size_t)length != have) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX,
                            "length mismatch (%s): header says %lu payload bytes, file has %zu",
                            (size_t)length > have ? "truncated" : "trailing bytes", (unsigned long)length, have);
    }
    if (length > SF_SITE_MAX_PAYLOAD) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX, "payload of %lu bytes exceeds the limit of %u",
                            (unsigned long)length, SF_SITE_MAX_PAYLOAD);
    }
    const uint32_t actual = sf_site_crc32(data + SF_SITE_HEADER_SIZE, have);
    if (actual != crc) {
        return sf_lcm_failf(err, err_size, name, SF_ESYNTAX,
                            "CRC-32 mismatch: header says 0x%08lx, payload has 0x%08lx", (unsigned long)crc,
                            (unsigned long)actual);
    }
    return SF_OK;
}

/* The core view of a decoded, checked site; builds store->ap_first. */
static int build_view(sf_site_store_t *const store, sf_site_t *const site, const char *const name,
                      char *const err, const size_t err_size)
{
    const stridefix_site_t *const s = &store->msg;
    store->ap_first = malloc(sizeof(int32_t) * ((size_t)s->n_ap + 1u));
    if (store->ap_first == NULL) {
        return sf_lcm_failf(err, err_size, name, SF_EIO, "out of memory for the AP index (%d APs)", (int)s->n_ap);
    }
    /* entry_ap is sorted (checked): ap_first[a] = first entry whose ap is ≥ a */
    int32_t i = 0;
    for (int32_t a = 0; a <= s->n_ap; a++) {
        while (i < s->n_entries && s->entry_ap[i] < a) {
            i++;
        }
        store->ap_first[a] = i;
    }
    site->map_rotation_deg = s->map_rotation_deg;
    site->lowest_floor = s->lowest_floor;
    site->n_floors = s->n_floors;
    site->floor_height_m = s->floor_height_m;
    site->fix_model = (sf_fix_model_t){.valid = s->has_fix_model,
                                       .floor_cov_m2 = {s->fix_floor_cov_m2[0], s->fix_floor_cov_m2[1],
                                                        s->fix_floor_cov_m2[2]},
                                       .cov_per_acc2 = {s->fix_cov_per_acc2[0], s->fix_cov_per_acc2[1],
                                                        s->fix_cov_per_acc2[2]},
                                       .bias_sigma_m = s->fix_bias_sigma_m,
                                       .bias_length_m = s->fix_bias_length_m,
                                       .white_share = s->fix_white_share};
    sf_radiomap_t *const m = &site->radiomap;
    m->n_ap = s->n_ap;
    m->ap_bssid = s->ap_bssid;
    m->ap_first = store->ap_first;
    m->n_rp = s->n_rp;
    m->rp_x_m = s->rp_x_m;
    m->rp_y_m = s->rp_y_m;
    m->rp_floor = s->rp_floor;
    m->rp_scans = s->rp_scans;
    m->n_entries = s->n_entries;
    m->entry_rp = s->entry_rp;
    m->entry_mean_dbm = s->entry_mean_dbm;
    m->entry_std_db = s->entry_std_db;
    m->entry_count = s->entry_count;
    sf_site_v2_view(s, site);
    sf_site_v3_view(s, site);
    const char *what = NULL;
    if (sf_radiomap_check(m, &what) != SF_OK) {
        return sf_lcm_failf(err, err_size, name, SF_ERANGE, "radio map check failed: %s", what != NULL ? what : "?");
    }
    /* the controller's own check, so a map it would refuse when attached is refused here, named */
    if (sf_cls_check_map(site, &what) != SF_OK) {
        return sf_lcm_failf(err, err_size, name, SF_ERANGE, "context map check failed: %s",
                            what != NULL ? what : "?");
    }
    return SF_OK;
}

int sf_site_parse(const uint8_t *const data, const size_t size, const char *const name,
                  sf_site_store_t *const store, sf_site_t *const site, char *const err, const size_t err_size)
{
    if (err != NULL && err_size > 0) {
        err[0] = '\0';
    }
    const char *const label = name != NULL ? name : "<site>";
    if ((data == NULL && size > 0) || store == NULL || site == NULL) {
        return sf_lcm_failf(err, err_size, label, SF_EINVAL, "sf_site_parse: NULL argument");
    }
    memset(store, 0, sizeof *store);
    memset(site, 0, sizeof *site);
    int rc = check_header(data, size, label, err, err_size);
    if (rc != SF_OK) {
        return rc;
    }
    const uint8_t *const payload = data + SF_SITE_HEADER_SIZE;
    const size_t length = size - SF_SITE_HEADER_SIZE;
    const int64_t want_hash = __stridefix_site_t_get_hash();
    if (length >= 8) {
        const uint64_t hi = (uint32_t)sf_lcm_be32(payload);
        const int64_t got_hash = (int64_t)((hi << 32) | (uint32_t)sf_lcm_be32(payload + 4));
        if (got_hash != want_hash) {
            return sf_lcm_failf(err, err_size, label, SF_ESYNTAX,
                                "payload is not a stridefix.site_t: LCM type hash 0x%016llx, expected 0x%016llx "
                                "(written with another version of site_t?)",
                                (unsigned long long)got_hash, (unsigned long long)want_hash);
        }
    }
    sf_lcm_walk_t w = {payload, length, 0, label, err, err_size};
    rc = walk_site(&w);
    if (rc != SF_OK) {
        return rc;
    }
    const int used = stridefix_site_t_decode(payload, 0, (int)length, &store->msg);
    if (used < 0) {
        stridefix_site_t_decode_cleanup(&store->msg); /* frees what was allocated before the failure */
        memset(store, 0, sizeof *store);
        return sf_lcm_failf(err, err_size, label, SF_ESYNTAX, "LCM decode of site_t failed (code %d)", used);
    }
    store->loaded = 1;
    if ((size_t)used != length) {
        sf_site_store_free(store);
        return sf_lcm_failf(err, err_size, label, SF_ESYNTAX, "LCM decode used %d of %zu payload bytes", used, length);
    }
    rc = check_fields(&store->msg, label, err, err_size);
    if (rc == SF_OK) {
        rc = build_view(store, site, label, err, err_size);
    }
    if (rc != SF_OK) {
        sf_site_store_free(store);
        memset(site, 0, sizeof *site);
    }
    return rc;
}

int sf_site_load(const char *const path, sf_site_store_t *const store, sf_site_t *const site, char *const err,
                 const size_t err_size)
{
    if (err != NULL && err_size > 0) {
        err[0] = '\0';
    }
    if (path == NULL || store == NULL || site == NULL) {
        return sf_lcm_failf(err, err_size, path != NULL ? path : "<site>", SF_EINVAL, "sf_site_load: NULL argument");
    }
    memset(store, 0, sizeof *store);
    memset(site, 0, sizeof *site);
    const int kind_rc = sf_file_check(path, "site file", true, err, err != NULL ? err_size : 0);
    if (kind_rc != SF_OK) {
        return kind_rc;
    }
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        const int e = errno;
        return sf_lcm_failf(err, err_size, path, e == ENOENT ? SF_ENOENT : SF_EIO, "cannot open site file: %s",
                            strerror(e));
    }
    /* read the whole file, growing the buffer, up to one byte more than the largest valid file */
    const size_t limit = (size_t)SF_SITE_HEADER_SIZE + SF_SITE_MAX_PAYLOAD + 1u;
    size_t cap = 1u << 16;
    size_t size = 0;
    uint8_t *buf = NULL;
    int rc = SF_OK;
    for (;;) {
        uint8_t *const bigger = realloc(buf, cap);
        if (bigger == NULL) {
            rc = sf_lcm_failf(err, err_size, path, SF_EIO, "out of memory reading the site file (%zu bytes)", cap);
            break;
        }
        buf = bigger;
        size += fread(buf + size, 1, cap - size, f);
        if (ferror(f)) {
            const int e = errno;
            rc = sf_lcm_failf(err, err_size, path, SF_EIO, "cannot read site file: %s", strerror(e));
            break;
        }
        if (size < cap || cap >= limit) {
            break; /* end of file, or more than any valid site file (check_header says so) */
        }
        cap = cap * 2u < limit ? cap * 2u : limit;
    }
    fclose(f);
    if (rc == SF_OK) {
        if (size >= limit) {
            rc = sf_lcm_failf(err, err_size, path, SF_ESYNTAX, "file is larger than the %zu-byte limit of a site file",
                              limit - 1u);
        } else {
            rc = sf_site_parse(buf, size, path, store, site, err, err_size);
        }
    }
    free(buf);
    return rc;
}
