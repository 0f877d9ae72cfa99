/* sf_rx_lcm.c — sf_rx_event_t ↔ the raw-sensor LCM types, one row per kind (see sf_rx_lcm.h). */
#include "sf_rx_lcm.h"

#include <inttypes.h>
#include <string.h>

#include "sf_error.h"
#include "sf_lcm_walk.h"
#include "stridefix_baro_t.h"
#include "stridefix_ble_scan_t.h"
#include "stridefix_gnss_t.h"
#include "stridefix_imu_t.h"
#include "stridefix_landmark_t.h"
#include "stridefix_mag_t.h"
#include "stridefix_wifi_scan_t.h"

/* Where a message goes: "<name>: <what>" into err. */
typedef struct {
    const char *name;
    char *err;
    size_t err_size;
} where_t;

/* The generated decode's result: SF_OK when it used all size bytes, else SF_ESYNTAX with a message.
 * The type fingerprint was checked before (check_type): a failed decode is a payload cut short. */
static int decoded(const int used, const int size, const char *const type, const where_t *const e)
{
    if (used < 0) {
        return sf_lcm_failf(e->err, e->err_size, e->name, SF_ESYNTAX, "payload of %d bytes is too short for a %s",
                            size, type);
    }
    if (used != size) {
        return sf_lcm_failf(e->err, e->err_size, e->name, SF_ESYNTAX, "payload has %d trailing bytes after the %s",
                            size - used, type);
    }
    return SF_OK;
}

/* ---- per kind: decode (LCM → event, 1 or SF_ESYNTAX) and encode (event → log) ---------------------- */

static int decode_imu(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_imu_t m;
    if (decoded(stridefix_imu_t_decode(data, 0, size, &m), size, "stridefix.imu_t", e) != SF_OK) {
        return SF_ESYNTAX;
    }
    ev->u.imu.t_us = m.t_us;
    ev->u.imu.seq = m.seq;
    memcpy(ev->u.imu.accel_mps2, m.accel_mps2, sizeof m.accel_mps2);
    memcpy(ev->u.imu.gyro_radps, m.gyro_radps, sizeof m.gyro_radps);
    return 1;
}

static void encode_imu(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                       const sf_rx_event_t *const ev)
{
    const sf_rx_imu_t *const s = &ev->u.imu;
    stridefix_imu_t msg = {.t_us = s->t_us, .seq = s->seq};
    memcpy(msg.accel_mps2, s->accel_mps2, sizeof msg.accel_mps2);
    memcpy(msg.gyro_radps, s->gyro_radps, sizeof msg.gyro_radps);
    SF_LCM_WRITE(out, channel, ts_us, stridefix_imu_t, &msg);
}

static int decode_mag(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_mag_t m;
    if (decoded(stridefix_mag_t_decode(data, 0, size, &m), size, "stridefix.mag_t", e) != SF_OK) {
        return SF_ESYNTAX;
    }
    ev->u.mag.t_us = m.t_us;
    ev->u.mag.seq = m.seq;
    memcpy(ev->u.mag.field_ut, m.field_ut, sizeof m.field_ut);
    return 1;
}

static void encode_mag(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                       const sf_rx_event_t *const ev)
{
    const sf_rx_mag_t *const s = &ev->u.mag;
    stridefix_mag_t msg = {.t_us = s->t_us, .seq = s->seq};
    memcpy(msg.field_ut, s->field_ut, sizeof msg.field_ut);
    SF_LCM_WRITE(out, channel, ts_us, stridefix_mag_t, &msg);
}

static int decode_baro(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_baro_t m;
    if (decoded(stridefix_baro_t_decode(data, 0, size, &m), size, "stridefix.baro_t", e) != SF_OK) {
        return SF_ESYNTAX;
    }
    ev->u.baro = (sf_rx_baro_t){m.t_us, m.seq, m.pressure_pa, m.temperature_degc};
    return 1;
}

static void encode_baro(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                        const sf_rx_event_t *const ev)
{
    const sf_rx_baro_t *const s = &ev->u.baro;
    stridefix_baro_t msg = {.t_us = s->t_us, .seq = s->seq, .pressure_pa = s->pressure_pa,
                            .temperature_degc = s->temperature_degc};
    SF_LCM_WRITE(out, channel, ts_us, stridefix_baro_t, &msg);
}

/* wifi_scan_t.lcm field by field (sf_lcm_walk.h says why); ble_scan_t is the other raw-sensor type
 * with a count. */
static int walk_wifi(const void *const data, const int size, const where_t *const e)
{
    sf_lcm_walk_t w = {data, (size_t)size, 0, e->name, e->err, e->err_size};
    int rc = sf_lcm_walk_skip(&w, 8, "type hash");
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(&w, 8 + 8 + 1, "t_us .. complete");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(&w, "n_ap", 8 + 4 + 4);
    return rc != SF_OK ? rc : sf_lcm_walk_end(&w, "stridefix.wifi_scan_t");
}

static int decode_wifi(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_wifi_scan_t m;
    if (walk_wifi(data, size, e) != SF_OK ||
        decoded(stridefix_wifi_scan_t_decode(data, 0, size, &m), size, "stridefix.wifi_scan_t", e) != SF_OK) {
        return SF_ESYNTAX; /* after the walk, the decode fails only on the type hash: nothing allocated */
    }
    sf_rx_wifi_t *const w = &ev->u.wifi;
    w->t_us = m.t_us;
    w->scan_id = m.scan_id;
    w->complete = m.complete != 0;
    w->n_ap = m.n_ap < SF_WIFI_MAX_AP ? m.n_ap : SF_WIFI_MAX_AP;
    for (int32_t i = 0; i < w->n_ap; i++) {
        w->bssid[i] = m.bssid[i];
        w->rssi_dbm[i] = m.rssi_dbm[i];
        w->freq_mhz[i] = m.freq_mhz[i];
    }
    stridefix_wifi_scan_t_decode_cleanup(&m);
    return 1;
}

static void encode_wifi(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                        const sf_rx_event_t *const ev)
{
    const sf_rx_wifi_t *const s = &ev->u.wifi;
    /* DEVIATION: the generated type has non-const array pointers; encoding only reads them. */
    stridefix_wifi_scan_t msg = {.t_us = s->t_us,
                                 .scan_id = s->scan_id,
                                 .complete = s->complete,
                                 .n_ap = s->n_ap,
                                 .bssid = (int64_t *)s->bssid,
                                 .rssi_dbm = (float *)s->rssi_dbm,
                                 .freq_mhz = (int32_t *)s->freq_mhz};
    SF_LCM_WRITE(out, channel, ts_us, stridefix_wifi_scan_t, &msg);
}

static int decode_gnss(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_gnss_t m;
    if (decoded(stridefix_gnss_t_decode(data, 0, size, &m), size, "stridefix.gnss_t", e) != SF_OK) {
        return SF_ESYNTAX;
    }
    ev->u.gnss = (sf_rx_gnss_t){m.t_us, m.lat_deg, m.lon_deg, m.alt_m, m.accuracy_m};
    return 1;
}

static void encode_gnss(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                        const sf_rx_event_t *const ev)
{
    const sf_rx_gnss_t *const s = &ev->u.gnss;
    stridefix_gnss_t msg = {.t_us = s->t_us, .lat_deg = s->lat_deg, .lon_deg = s->lon_deg, .alt_m = s->alt_m,
                            .accuracy_m = s->accuracy_m};
    SF_LCM_WRITE(out, channel, ts_us, stridefix_gnss_t, &msg);
}

/* ble_scan_t.lcm field by field. */
static int walk_ble(const void *const data, const int size, const where_t *const e)
{
    sf_lcm_walk_t w = {data, (size_t)size, 0, e->name, e->err, e->err_size};
    int rc = sf_lcm_walk_skip(&w, 8, "type hash");
    rc = rc != SF_OK ? rc : sf_lcm_walk_skip(&w, 8, "t_us");
    rc = rc != SF_OK ? rc : sf_lcm_walk_count(&w, "n", 8 + 4);
    return rc != SF_OK ? rc : sf_lcm_walk_end(&w, "stridefix.ble_scan_t");
}

static int decode_ble(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_ble_scan_t m;
    if (walk_ble(data, size, e) != SF_OK ||
        decoded(stridefix_ble_scan_t_decode(data, 0, size, &m), size, "stridefix.ble_scan_t", e) != SF_OK) {
        return SF_ESYNTAX; /* after the walk, the decode fails only on the type hash: nothing allocated */
    }
    sf_rx_ble_t *const b = &ev->u.ble;
    b->t_us = m.t_us;
    b->n = m.n < SF_BLE_MAX_BEACONS ? m.n : SF_BLE_MAX_BEACONS;
    for (int32_t i = 0; i < b->n; i++) {
        b->beacon_id[i] = m.beacon_id[i];
        b->rssi_dbm[i] = m.rssi_dbm[i];
    }
    stridefix_ble_scan_t_decode_cleanup(&m);
    return 1;
}

static void encode_ble(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                       const sf_rx_event_t *const ev)
{
    const sf_rx_ble_t *const s = &ev->u.ble;
    /* DEVIATION: the generated type has non-const array pointers; encoding only reads them. */
    stridefix_ble_scan_t msg = {
        .t_us = s->t_us, .n = s->n, .beacon_id = (int64_t *)s->beacon_id, .rssi_dbm = (float *)s->rssi_dbm};
    SF_LCM_WRITE(out, channel, ts_us, stridefix_ble_scan_t, &msg);
}

static int decode_landmark(const void *const data, const int size, sf_rx_event_t *const ev, const where_t *const e)
{
    stridefix_landmark_t m;
    if (decoded(stridefix_landmark_t_decode(data, 0, size, &m), size, "stridefix.landmark_t", e) != SF_OK) {
        return SF_ESYNTAX;
    }
    ev->u.landmark = (sf_rx_landmark_t){m.t_us, m.landmark_id, m.x_m, m.y_m, m.floor, m.accuracy_m};
    return 1;
}

static void encode_landmark(sf_lcm_out_t *const out, const char *const channel, const int64_t ts_us,
                            const sf_rx_event_t *const ev)
{
    const sf_rx_landmark_t *const s = &ev->u.landmark;
    stridefix_landmark_t msg = {.t_us = s->t_us,
                                .landmark_id = s->landmark_id,
                                .x_m = s->x_m,
                                .y_m = s->y_m,
                                .floor = s->floor,
                                .accuracy_m = s->accuracy_m};
    SF_LCM_WRITE(out, channel, ts_us, stridefix_landmark_t, &msg);
}

/* ---- per kind: the LCM type (name and fingerprint, the first 8 bytes of every encoding) ------------ */

/* DEVIATION: __<type>_get_hash is the generated C API's only way to the fingerprint (reserved-looking
 * name, lcm-gen's). */
#define SF_RX_TYPE(kind, lcm_type) \
    static const char *type_name_##kind(void) { return "stridefix." #lcm_type; } \
    static int64_t type_hash_##kind(void) { return __stridefix_##lcm_type##_get_hash(); }
SF_RX_TYPE(imu, imu_t)
SF_RX_TYPE(mag, mag_t)
SF_RX_TYPE(baro, baro_t)
SF_RX_TYPE(wifi, wifi_scan_t)
SF_RX_TYPE(gnss, gnss_t)
SF_RX_TYPE(ble, ble_scan_t)
SF_RX_TYPE(landmark, landmark_t)
#undef SF_RX_TYPE

/* ---- the table, generated from SF_RX_KINDS ------------------------------------------------------- */

typedef struct {
    sf_rx_kind_t kind;
    const char *channel;
    int (*decode)(const void *data, int size, sf_rx_event_t *ev, const where_t *e);
    void (*encode)(sf_lcm_out_t *out, const char *channel, int64_t ts_us, const sf_rx_event_t *ev);
    const char *(*type_name)(void);
    int64_t (*type_hash)(void);
} kind_row_t;

static const kind_row_t kind_rows[] = {
#define SF_RX_KIND_ROW(kind, channel) \
    {sf_rx_##kind, channel, decode_##kind, encode_##kind, type_name_##kind, type_hash_##kind},
    SF_RX_KINDS(SF_RX_KIND_ROW)
#undef SF_RX_KIND_ROW
};
_Static_assert(sizeof kind_rows / sizeof kind_rows[0] == SF_RX_KIND_COUNT, "one row per SF_RX_KINDS entry");

static const kind_row_t *row_of_kind(const sf_rx_kind_t kind)
{
    const int i = (int)kind - 1; /* rows follow the enum: kind k is row k - 1 */
    return i >= 0 && i < SF_RX_KIND_COUNT ? &kind_rows[i] : NULL;
}

const char *sf_rx_lcm_channel(const sf_rx_kind_t kind)
{
    const kind_row_t *const row = row_of_kind(kind);
    return row != NULL ? row->channel : NULL;
}

/* The payload's type fingerprint against the channel's type, before any field is read as that type
 * would have it (another type's bytes would otherwise be reported as a bad count or a short payload):
 * SF_OK, or SF_ESYNTAX naming the type the payload is when it is one of the raw-sensor types. */
static int check_type(const kind_row_t *const row, const uint8_t *const p, const size_t size,
                      const where_t *const e)
{
    if (size < 8) {
        return sf_lcm_failf(e->err, e->err_size, e->name, SF_ESYNTAX,
                            "payload of %zu bytes is too short for a %s (no type fingerprint)", size,
                            row->type_name());
    }
    const uint64_t got = (uint64_t)(uint32_t)sf_lcm_be32(p) << 32 | (uint32_t)sf_lcm_be32(p + 4);
    if (got == (uint64_t)row->type_hash()) {
        return SF_OK;
    }
    for (size_t i = 0; i < sizeof kind_rows / sizeof kind_rows[0]; i++) {
        if (got == (uint64_t)kind_rows[i].type_hash()) {
            return sf_lcm_failf(e->err, e->err_size, e->name, SF_ESYNTAX, "payload is a %s, not a %s",
                                kind_rows[i].type_name(), row->type_name());
        }
    }
    return sf_lcm_failf(e->err, e->err_size, e->name, SF_ESYNTAX,
                        "payload is not a %s (type fingerprint 0x%016" PRIx64 ", expected 0x%016" PRIx64 ")",
                        row->type_name(), got, (uint64_t)row->type_hash());
}

int sf_rx_lcm_decode(const char *const channel, const void *const data, const size_t size,
                     sf_rx_event_t *const ev, const char *const name, char *const err, const size_t err_size)
{
    const where_t e = {name != NULL ? name : channel, err, err_size};
    for (size_t i = 0; i < sizeof kind_rows / sizeof kind_rows[0]; i++) {
        if (strcmp(channel, kind_rows[i].channel) == 0) {
            if (size > (size_t)INT32_MAX) {
                return sf_lcm_failf(err, err_size, e.name, SF_ESYNTAX, "payload of %zu bytes is too large", size);
            }
            if (check_type(&kind_rows[i], data, size, &e) != SF_OK ||
                kind_rows[i].decode(data, (int)size, ev, &e) != 1) {
                return SF_ESYNTAX;
            }
            ev->kind = kind_rows[i].kind;
            return 1;
        }
    }
    return 0;
}

void sf_rx_lcm_write(sf_lcm_out_t *const out, const int64_t ts_us, const sf_rx_event_t *const ev)
{
    const kind_row_t *const row = row_of_kind(ev->kind);
    if (row != NULL) {
        row->encode(out, row->channel, ts_us, ev);
    }
}
