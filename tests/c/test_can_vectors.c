/* test_can_vectors.c — the generated C codec and sf_board_rx against cantools' Python encoder.
 *
 * tests/vectors/gen_can_vectors.py writes, for every message of firmware/board.dbc, frames that
 * cantools encoded from known signal values (zeros, min, max, seeded random). Here each frame is
 * unpacked with the C that cantools generated (board_<msg>_unpack + *_decode): every signal must
 * equal the Python value to half a scale step, and board_<msg>_pack of the unpacked struct must give
 * the same bytes. Then the frame goes through sf_board_rx_frame, and the event must carry the same
 * values in the documented units (gyro in rad/s).
 *
 * Usage: test_can_vectors VECTORS_TXT */
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

#include "board.h"
#include "sf_board_rx.h"
#include "sf_error.h"
#include "sf_test_frames.h"

#define MAX_VECTORS 1024
#define MAX_SIGNALS 16
#define N_MESSAGES 13
#define DEG_TO_RAD (3.14159265358979323846 / 180.0)

typedef struct {
    uint32_t id;
    uint8_t data[8];
    int n;
    char name[MAX_SIGNALS][32];
    double value[MAX_SIGNALS];
    int line_no;
} vector_t;

static const char *g_path;
static vector_t g_vec[MAX_VECTORS];
static int g_nvec;

/* The Python value of signal `name` in *v; fails the test when absent. */
static double py(const vector_t *const v, const char *const name)
{
    for (int i = 0; i < v->n; i++) {
        if (strcmp(v->name[i], name) == 0) {
            return v->value[i];
        }
    }
    fail_msg("line %d: no signal '%s'", v->line_no, name);
    return NAN;
}

static int load_vectors(void **state)
{
    (void)state;
    FILE *const f = fopen(g_path, "r");
    if (f == NULL) {
        fprintf(stderr, "%s: cannot open the vectors file\n", g_path);
        return -1;
    }
    char line[1024];
    int line_no = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        line_no++;
        if (g_nvec == MAX_VECTORS) {
            fprintf(stderr, "%s: more than %d vectors\n", g_path, MAX_VECTORS);
            fclose(f);
            return -1;
        }
        vector_t *const v = &g_vec[g_nvec];
        memset(v, 0, sizeof *v);
        v->line_no = line_no;
        char *save = NULL;
        const char *const id = strtok_r(line, " \n", &save);
        const char *const data = strtok_r(NULL, " \n", &save);
        if (id == NULL || data == NULL || strlen(data) != 16) {
            fprintf(stderr, "%s:%d: bad vector line\n", g_path, line_no);
            fclose(f);
            return -1;
        }
        v->id = (uint32_t)strtoul(id, NULL, 16);
        for (int i = 0; i < 8; i++) {
            char byte[3] = {data[2 * i], data[2 * i + 1], '\0'};
            v->data[i] = (uint8_t)strtoul(byte, NULL, 16);
        }
        char *tok;
        while ((tok = strtok_r(NULL, " \n", &save)) != NULL) {
            char *const eq = strchr(tok, '=');
            if (eq == NULL || v->n == MAX_SIGNALS) {
                fprintf(stderr, "%s:%d: bad signal '%s'\n", g_path, line_no, tok);
                fclose(f);
                return -1;
            }
            *eq = '\0';
            snprintf(v->name[v->n], sizeof v->name[v->n], "%s", tok);
            v->value[v->n] = strtod(eq + 1, NULL);
            v->n++;
        }
        g_nvec++;
    }
    fclose(f);
    return 0;
}

/* ---- The generated codec, one adapter per message: unpack → (name, value, step) list → pack. ---- */

typedef struct {
    const char *name;
    double value;
    double step; /* one raw unit in physical units (the scale) */
} field_t;

typedef int (*codec_fn)(const uint8_t data[8], field_t *fields, int *n, uint8_t repacked[8]);

#define CODEC_BEGIN(msg)                                                                                  \
    static int codec_##msg(const uint8_t data[8], field_t *const fields, int *const n, uint8_t repacked[8]) \
    {                                                                                                     \
        struct board_##msg##_t m;                                                                         \
        memset(&m, 0, sizeof m);                                                                          \
        if (board_##msg##_unpack(&m, data, 8) != 0) {                                                     \
            return -1;                                                                                    \
        }                                                                                                 \
        *n = 0;
#define SIG(msg, s)                                                                                           \
    fields[(*n)++] = (field_t){#s, board_##msg##_##s##_decode(m.s),                                          \
                              board_##msg##_##s##_decode(1) - board_##msg##_##s##_decode(0)};
#define CODEC_END(msg)                            \
    return board_##msg##_pack(repacked, &m, 8); \
    }

CODEC_BEGIN(board_time) SIG(board_time, time_ms) SIG(board_time, boot_id) CODEC_END(board_time)
CODEC_BEGIN(imu_accel) SIG(imu_accel, accel_x) SIG(imu_accel, accel_y) SIG(imu_accel, accel_z) SIG(imu_accel, seq)
    SIG(imu_accel, t_lo_ms) CODEC_END(imu_accel)
CODEC_BEGIN(imu_gyro) SIG(imu_gyro, gyro_x) SIG(imu_gyro, gyro_y) SIG(imu_gyro, gyro_z) SIG(imu_gyro, seq)
    SIG(imu_gyro, t_lo_ms) CODEC_END(imu_gyro)
CODEC_BEGIN(mag) SIG(mag, mag_x) SIG(mag, mag_y) SIG(mag, mag_z) SIG(mag, seq) SIG(mag, t_lo_ms) CODEC_END(mag)
CODEC_BEGIN(baro) SIG(baro, pressure) SIG(baro, temperature) SIG(baro, seq) SIG(baro, t_lo_ms) CODEC_END(baro)
CODEC_BEGIN(wifi_scan_begin) SIG(wifi_scan_begin, scan_id) SIG(wifi_scan_begin, time_ms) CODEC_END(wifi_scan_begin)
CODEC_BEGIN(wifi_ap) SIG(wifi_ap, bssid) SIG(wifi_ap, rssi) SIG(wifi_ap, channel) CODEC_END(wifi_ap)
CODEC_BEGIN(wifi_scan_end) SIG(wifi_scan_end, scan_id) SIG(wifi_scan_end, n_ap) CODEC_END(wifi_scan_end)
CODEC_BEGIN(gnss_position) SIG(gnss_position, latitude) SIG(gnss_position, longitude) CODEC_END(gnss_position)
CODEC_BEGIN(gnss_info) SIG(gnss_info, time_ms) SIG(gnss_info, altitude) SIG(gnss_info, accuracy)
    CODEC_END(gnss_info)
CODEC_BEGIN(ble_adv) SIG(ble_adv, beacon_id) SIG(ble_adv, rssi) SIG(ble_adv, t_lo_ms) CODEC_END(ble_adv)
CODEC_BEGIN(landmark) SIG(landmark, x) SIG(landmark, y) SIG(landmark, floor) SIG(landmark, t_lo_ms) CODEC_END(landmark)
CODEC_BEGIN(board_status) SIG(board_status, tx_overflows) SIG(board_status, board_temp) SIG(board_status, fw_major)
    SIG(board_status, fw_minor) SIG(board_status, imu_ok) SIG(board_status, mag_ok) SIG(board_status, baro_ok)
        SIG(board_status, wifi_ok) CODEC_END(board_status)

static const struct {
    uint32_t id;
    const char *name;
    codec_fn codec;
} k_codecs[N_MESSAGES] = {
    {BOARD_BOARD_TIME_FRAME_ID, "BOARD_TIME", codec_board_time},
    {BOARD_IMU_ACCEL_FRAME_ID, "IMU_ACCEL", codec_imu_accel},
    {BOARD_IMU_GYRO_FRAME_ID, "IMU_GYRO", codec_imu_gyro},
    {BOARD_MAG_FRAME_ID, "MAG", codec_mag},
    {BOARD_BARO_FRAME_ID, "BARO", codec_baro},
    {BOARD_WIFI_SCAN_BEGIN_FRAME_ID, "WIFI_SCAN_BEGIN", codec_wifi_scan_begin},
    {BOARD_WIFI_AP_FRAME_ID, "WIFI_AP", codec_wifi_ap},
    {BOARD_WIFI_SCAN_END_FRAME_ID, "WIFI_SCAN_END", codec_wifi_scan_end},
    {BOARD_GNSS_POSITION_FRAME_ID, "GNSS_POSITION", codec_gnss_position},
    {BOARD_GNSS_INFO_FRAME_ID, "GNSS_INFO", codec_gnss_info},
    {BOARD_BLE_ADV_FRAME_ID, "BLE_ADV", codec_ble_adv},
    {BOARD_LANDMARK_FRAME_ID, "LANDMARK", codec_landmark},
    {BOARD_BOARD_STATUS_FRAME_ID, "BOARD_STATUS", codec_board_status},
};

static int codec_index(const uint32_t id)
{
    for (int i = 0; i < N_MESSAGES; i++) {
        if (k_codecs[i].id == id) {
            return i;
        }
    }
    return -1;
}

/* The scale of signal `name` of message id, from the generated decoder. */
static double step_of(const vector_t *const v, const char *const name)
{
    field_t fields[MAX_SIGNALS];
    int n = 0;
    uint8_t repacked[8];
    assert_true(k_codecs[codec_index(v->id)].codec(v->data, fields, &n, repacked) >= 0);
    for (int i = 0; i < n; i++) {
        if (strcmp(fields[i].name, name) == 0) {
            return fields[i].step;
        }
    }
    fail_msg("line %d: no step for '%s'", v->line_no, name);
    return NAN;
}

static void assert_close(const double got, const double want, const double tol, const vector_t *const v,
                         const char *const what)
{
    if (!(fabs(got - want) <= tol)) {
        fail_msg("line %d (id 0x%03X) %s: got %.17g, want %.17g (tolerance %.3g)", v->line_no, (unsigned)v->id, what,
                 got, want, tol);
    }
}

/* Every message has vectors, and no vector has an id outside the DBC. */
static void test_vectors_cover_every_message(void **state)
{
    (void)state;
    int count[N_MESSAGES] = {0};
    for (int i = 0; i < g_nvec; i++) {
        const int k = codec_index(g_vec[i].id);
        if (k < 0) {
            fail_msg("line %d: id 0x%03X is not in board.dbc", g_vec[i].line_no, (unsigned)g_vec[i].id);
        }
        count[k]++;
    }
    for (int k = 0; k < N_MESSAGES; k++) {
        if (count[k] < 11) { /* zeros, min, max + 8 random */
            fail_msg("%s: %d vectors, want at least 11", k_codecs[k].name, count[k]);
        }
    }
    assert_int_equal(g_nvec, 13 * 11 + 2); /* + the typical BLE_ADV and LANDMARK */
}

/* C unpack + decode equals Python's values; C pack of the unpacked struct equals Python's bytes. */
static void test_vectors_unpack_and_repack(void **state)
{
    (void)state;
    for (int i = 0; i < g_nvec; i++) {
        const vector_t *const v = &g_vec[i];
        field_t fields[MAX_SIGNALS];
        int n = 0;
        uint8_t repacked[8] = {0};
        const int packed = k_codecs[codec_index(v->id)].codec(v->data, fields, &n, repacked);
        assert_int_equal(packed, 8);
        assert_int_equal(n, v->n); /* the C struct and the vector name the same signals */
        for (int j = 0; j < n; j++) {
            assert_close(fields[j].value, py(v, fields[j].name), fields[j].step / 2, v, fields[j].name);
        }
        if (memcmp(repacked, v->data, 8) != 0) {
            fail_msg("line %d (id 0x%03X): repacked %02X%02X%02X%02X%02X%02X%02X%02X", v->line_no, (unsigned)v->id,
                     repacked[0], repacked[1], repacked[2], repacked[3], repacked[4], repacked[5], repacked[6],
                     repacked[7]);
        }
    }
}

/* The bytes of vector v as a received frame. */
static sf_can_frame_t frame_of(const vector_t *const v)
{
    sf_can_frame_t f = tf_frame(v->id);
    memcpy(f.data, v->data, 8);
    return f;
}

/* A sample's time from its low 8 bits: the value ≡ t_lo (mod 256) within ±128 ms of board_ms. */
static void assert_sample_time(const int64_t t_us, const int64_t board_ms, const double t_lo, const vector_t *const v)
{
    const int64_t t_ms = t_us / 1000;
    assert_int_equal(t_us % 1000, 0);
    assert_int_equal((t_ms % 256 + 256) % 256, (int64_t)t_lo);
    if (llabs(t_ms - board_ms) > 128) {
        fail_msg("line %d: sample time %lld ms, more than 128 ms from board time %lld", v->line_no, (long long)t_ms,
                 (long long)board_ms);
    }
}

static void rx_one(const vector_t *const v)
{
    sf_board_rx_t *const rx = malloc(sizeof *rx); /* ≈ 5 KiB: not on the stack */
    sf_rx_event_t *const ev = malloc(sizeof *ev);
    assert_non_null(rx);
    assert_non_null(ev);
    sf_board_rx_init(rx);
    const sf_can_frame_t f = frame_of(v);
    const uint32_t t0 = 100000; /* board time of the BOARD_TIME sent first */
    sf_can_frame_t tmp;

    switch (v->id) {
    case BOARD_BOARD_TIME_FRAME_ID:
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 0);
        assert_true(rx->clock.synced);
        assert_int_equal(rx->clock.board_ms, (int64_t)py(v, "time_ms"));
        assert_int_equal(rx->clock.boot_id, (int)py(v, "boot_id"));
        break;
    case BOARD_IMU_ACCEL_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 0); /* waits for its gyro half */
        tmp = tf_gyro((uint8_t)py(v, "seq"), (uint8_t)py(v, "t_lo_ms"), 10.0, -20.0, 30.0);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 1);
        assert_int_equal(ev->kind, sf_rx_imu);
        const double step = step_of(v, "accel_x");
        assert_close(ev->u.imu.accel_mps2[0], py(v, "accel_x"), step / 2, v, "event accel_x [m/s2]");
        assert_close(ev->u.imu.accel_mps2[1], py(v, "accel_y"), step / 2, v, "event accel_y [m/s2]");
        assert_close(ev->u.imu.accel_mps2[2], py(v, "accel_z"), step / 2, v, "event accel_z [m/s2]");
        const double gstep = board_imu_gyro_gyro_x_decode(1) * DEG_TO_RAD;
        assert_close(ev->u.imu.gyro_radps[0], 10.0 * DEG_TO_RAD, gstep / 2, v, "event gyro_x [rad/s]");
        assert_close(ev->u.imu.gyro_radps[1], -20.0 * DEG_TO_RAD, gstep / 2, v, "event gyro_y [rad/s]");
        assert_close(ev->u.imu.gyro_radps[2], 30.0 * DEG_TO_RAD, gstep / 2, v, "event gyro_z [rad/s]");
        assert_sample_time(ev->u.imu.t_us, t0, py(v, "t_lo_ms"), v);
        assert_int_equal(ev->u.imu.seq, (int64_t)py(v, "seq"));
        break;
    }
    case BOARD_IMU_GYRO_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        tmp = tf_accel((uint8_t)py(v, "seq"), (uint8_t)py(v, "t_lo_ms"), 0.0, 0.0, 9.81);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_imu);
        const double step = step_of(v, "gyro_x") * DEG_TO_RAD;
        assert_close(ev->u.imu.gyro_radps[0], py(v, "gyro_x") * DEG_TO_RAD, step / 2, v, "event gyro_x [rad/s]");
        assert_close(ev->u.imu.gyro_radps[1], py(v, "gyro_y") * DEG_TO_RAD, step / 2, v, "event gyro_y [rad/s]");
        assert_close(ev->u.imu.gyro_radps[2], py(v, "gyro_z") * DEG_TO_RAD, step / 2, v, "event gyro_z [rad/s]");
        assert_close(ev->u.imu.accel_mps2[2], 9.81, board_imu_accel_accel_z_decode(1) / 2, v, "event accel_z");
        assert_sample_time(ev->u.imu.t_us, t0, py(v, "t_lo_ms"), v);
        break;
    }
    case BOARD_MAG_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_mag);
        const double step = step_of(v, "mag_x");
        assert_close(ev->u.mag.field_ut[0], py(v, "mag_x"), step / 2, v, "event mag_x [uT]");
        assert_close(ev->u.mag.field_ut[1], py(v, "mag_y"), step / 2, v, "event mag_y [uT]");
        assert_close(ev->u.mag.field_ut[2], py(v, "mag_z"), step / 2, v, "event mag_z [uT]");
        assert_sample_time(ev->u.mag.t_us, t0, py(v, "t_lo_ms"), v);
        break;
    }
    case BOARD_BARO_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_baro);
        assert_close(ev->u.baro.pressure_pa, py(v, "pressure"), step_of(v, "pressure") / 2, v, "event pressure [Pa]");
        assert_close(ev->u.baro.temperature_degc, py(v, "temperature"), step_of(v, "temperature") / 2, v,
                     "event temperature [degC]");
        assert_sample_time(ev->u.baro.t_us, t0, py(v, "t_lo_ms"), v);
        break;
    }
    case BOARD_WIFI_SCAN_BEGIN_FRAME_ID: {
        const uint32_t scan_t = (uint32_t)py(v, "time_ms");
        tmp = tf_board_time(scan_t, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 0);
        tmp = tf_scan_ap(0x0123456789ABu, -60, 6);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        tmp = tf_scan_end((uint8_t)py(v, "scan_id"), 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 1);
        assert_int_equal(ev->kind, sf_rx_wifi);
        assert_int_equal(ev->u.wifi.t_us, (int64_t)scan_t * 1000);
        assert_int_equal(ev->u.wifi.scan_id, (int64_t)py(v, "scan_id"));
        assert_true(ev->u.wifi.complete);
        assert_int_equal(ev->u.wifi.n_ap, 1);
        break;
    }
    case BOARD_WIFI_AP_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        tmp = tf_scan_begin(7, t0);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        const int32_t mhz = sf_wifi_channel_to_mhz((unsigned)py(v, "channel"));
        const bool valid = mhz != 0 && py(v, "rssi") < 0;
        const int rc = sf_board_rx_frame(rx, &f, ev);
        if (!valid) { /* channel 0, 15..31, > 177, or rssi >= 0: a decode error */
            assert_int_equal(rc, SF_ERANGE);
            assert_int_equal(rx->counters.decode_errors, 1);
            break;
        }
        assert_int_equal(rc, 0);
        tmp = tf_scan_end(7, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 1);
        assert_int_equal(ev->u.wifi.n_ap, 1);
        assert_int_equal(ev->u.wifi.bssid[0], (int64_t)py(v, "bssid"));
        assert_close(ev->u.wifi.rssi_dbm[0], py(v, "rssi"), 0.5, v, "event rssi [dBm]");
        assert_int_equal(ev->u.wifi.freq_mhz[0], mhz);
        break;
    }
    case BOARD_WIFI_SCAN_END_FRAME_ID: {
        const int n_ap = (int)py(v, "n_ap");
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        tmp = tf_scan_begin((uint8_t)py(v, "scan_id"), t0);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        for (int i = 0; i < n_ap; i++) {
            tmp = tf_scan_ap((uint64_t)i + 1, -40, 11);
            assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        }
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_wifi);
        assert_true(ev->u.wifi.complete);
        assert_int_equal(ev->u.wifi.n_ap, n_ap);
        break;
    }
    case BOARD_GNSS_POSITION_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        tmp = tf_gnss_info(t0, 12.3, 4.5);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_gnss);
        assert_close(ev->u.gnss.lat_deg, py(v, "latitude"), step_of(v, "latitude") / 2, v, "event latitude");
        assert_close(ev->u.gnss.lon_deg, py(v, "longitude"), step_of(v, "longitude") / 2, v, "event longitude");
        assert_int_equal(ev->u.gnss.t_us, (int64_t)t0 * 1000);
        break;
    }
    case BOARD_GNSS_INFO_FRAME_ID: {
        const uint32_t fix_t = (uint32_t)py(v, "time_ms");
        tmp = tf_board_time(fix_t, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 0);
        tmp = tf_gnss_position(48.0, 11.0);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 1);
        assert_int_equal(ev->kind, sf_rx_gnss);
        assert_int_equal(ev->u.gnss.t_us, (int64_t)fix_t * 1000);
        assert_close(ev->u.gnss.alt_m, py(v, "altitude"), step_of(v, "altitude") / 2, v, "event altitude [m]");
        /* accuracy is a float in the event: allow its rounding on top of half a step */
        assert_close(ev->u.gnss.accuracy_m, py(v, "accuracy"), step_of(v, "accuracy") / 2 + 1e-4, v,
                     "event accuracy [m]");
        break;
    }
    case BOARD_BLE_ADV_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        const bool valid = py(v, "beacon_id") != 0.0 && py(v, "rssi") < 0;
        const int rc = sf_board_rx_frame(rx, &f, ev);
        if (!valid) { /* MAC 0, or rssi >= 0 dBm: a decode error */
            assert_int_equal(rc, SF_ERANGE);
            assert_int_equal(rx->counters.decode_errors, 1);
            break;
        }
        assert_int_equal(rc, 0); /* in the open window */
        assert_int_equal(sf_board_rx_flush(rx, ev), 1);
        assert_int_equal(ev->kind, sf_rx_ble);
        assert_int_equal(ev->u.ble.n, 1);
        assert_int_equal(ev->u.ble.beacon_id[0], (int64_t)py(v, "beacon_id"));
        assert_close(ev->u.ble.rssi_dbm[0], py(v, "rssi"), 0.5, v, "event rssi [dBm]");
        assert_sample_time(ev->u.ble.t_us, t0, py(v, "t_lo_ms"), v);
        break;
    }
    case BOARD_LANDMARK_FRAME_ID: {
        tmp = tf_board_time(t0, 1);
        assert_int_equal(sf_board_rx_frame(rx, &tmp, ev), 0);
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 1);
        assert_int_equal(ev->kind, sf_rx_landmark);
        assert_close(ev->u.landmark.x_m, py(v, "x"), step_of(v, "x") / 2, v, "event x [m]");
        assert_close(ev->u.landmark.y_m, py(v, "y"), step_of(v, "y") / 2, v, "event y [m]");
        assert_int_equal(ev->u.landmark.floor, (int)py(v, "floor"));
        assert_sample_time(ev->u.landmark.t_us, t0, py(v, "t_lo_ms"), v);
        break;
    }
    case BOARD_BOARD_STATUS_FRAME_ID:
        assert_int_equal(sf_board_rx_frame(rx, &f, ev), 0);
        assert_int_equal(rx->counters.board_status, 1);
        assert_int_equal(rx->counters.board_tx_overflows, (uint64_t)py(v, "tx_overflows"));
        break;
    default:
        fail_msg("line %d: id 0x%03X", v->line_no, (unsigned)v->id);
    }
    assert_int_equal(rx->counters.unknown_id, 0);
    assert_int_equal(rx->counters.bad_length, 0);
    free(ev);
    free(rx);
}

static void test_vectors_through_board_rx(void **state)
{
    (void)state;
    for (int i = 0; i < g_nvec; i++) {
        rx_one(&g_vec[i]);
    }
}

int main(int argc, char **argv)
{
#ifdef SF_CAN_VECTORS
    g_path = SF_CAN_VECTORS;
#endif
    if (argc > 1) {
        g_path = argv[1];
    }
    if (g_path == NULL) {
        fprintf(stderr, "usage: %s VECTORS_TXT\n", argv[0]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vectors_cover_every_message),
        cmocka_unit_test(test_vectors_unpack_and_repack),
        cmocka_unit_test(test_vectors_through_board_rx),
    };
    return cmocka_run_group_tests(tests, load_vectors, NULL);
}
