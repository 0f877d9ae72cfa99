/* sf_board_rx.c — decoding, timing and reassembly of board frames (see sf_board_rx.h).
 * The bit layouts live only in board.dbc; board.h/board.c are generated from it by cantools. */
#include "sf_board_rx.h"

#include <string.h>

#include "board.h"
#include "sf_board_ble.h"
#include "sf_error.h"

#define DEG_TO_RAD (3.14159265358979323846 / 180.0)

/* Nominal periods (board.dbc's GenMsgCycleTime) only seed the learnt period: the board may run mag
 * and baro at other rates. */
#define IMU_PERIOD_MS ((double)BOARD_IMU_ACCEL_CYCLE_TIME_MS)
#define MAG_PERIOD_MS ((double)BOARD_MAG_CYCLE_TIME_MS)
#define BARO_PERIOD_MS ((double)BOARD_BARO_CYCLE_TIME_MS)
_Static_assert(BOARD_IMU_ACCEL_CYCLE_TIME_MS == BOARD_IMU_GYRO_CYCLE_TIME_MS, "one IMU sample is an ACCEL and a GYRO frame");
/* No frame for this long is a silence of the bus (the board sends at least 100 IMU frames a second). */
#define SILENCE_US 1000000

void sf_board_rx_init(sf_board_rx_t *const rx)
{
    memset(rx, 0, sizeof *rx);
    sf_board_clock_init(&rx->clock);
    sf_stream_time_init(&rx->imu_time, IMU_PERIOD_MS);
    sf_stream_time_init(&rx->mag_time, MAG_PERIOD_MS);
    sf_stream_time_init(&rx->baro_time, BARO_PERIOD_MS);
    sf_params_t p;
    sf_params_default(&p);
    sf_board_rx_configure(rx, &p);
}

void sf_board_rx_configure(sf_board_rx_t *const rx, const sf_params_t *const p)
{
    rx->ble_window_us = (int64_t)p->ble_window_ms * 1000;
    rx->landmark_accuracy_m = (float)p->landmark_accuracy_m;
}

int sf_board_rx_flush(sf_board_rx_t *const rx, sf_rx_event_t *const ev)
{
    ev->kind = sf_rx_none;
    const int rc = sf_board_ble_close(rx, ev);
    if (rc == 1) {
        sf_rx_count_sample(&rx->counters, ev->kind);
    }
    return rc;
}

/* A new epoch (the board restarted): what was in flight belongs to the old boot. */
static void on_new_epoch(sf_board_rx_t *const rx)
{
    memset(rx->accel, 0, sizeof rx->accel);
    memset(rx->gyro, 0, sizeof rx->gyro);
    sf_board_scan_on_new_epoch(&rx->scan, &rx->counters);
    rx->gnss_info_valid = false;
}

/* Gives a sample its time; counts gaps and sync, duplicate, late and corrupt-seq problems. */
static int resolve(sf_board_rx_t *const rx, sf_stream_time_t *const st, const uint8_t seq, const uint8_t t_lo,
                   int64_t *const t_us, int64_t *const useq)
{
    int64_t t_ms;
    uint32_t lost;
    const int rc = sf_stream_time_resolve(st, &rx->clock, seq, t_lo, rx->host_t_us, &t_ms, useq, &lost);
    switch (rc) {
    case SF_OK: break;
    case SF_ENOTSYNC: rx->counters.unsynced++; return rc;
    case SF_EDUPLICATE: rx->counters.duplicates++; return rc;
    case SF_ELATE: rx->counters.late++; return rc;
    default: rx->counters.seq_rejected++; return rc;
    }
    rx->counters.seq_gaps += lost;
    *t_us = sf_board_clock_output_us(&rx->clock, t_ms);
    return SF_OK;
}

/* Drops the halves of buf older than seq: their partners can no longer come in time. */
static void drop_older(sf_board_rx_t *const rx, sf_imu_half_t buf[SF_IMU_HALVES], const uint8_t seq)
{
    for (int i = 0; i < SF_IMU_HALVES; i++) {
        if (buf[i].valid && (int8_t)(uint8_t)(seq - buf[i].seq) > 0) {
            buf[i].valid = false;
            rx->counters.imu_unpaired++;
        }
    }
}

/* Pairs IMU_ACCEL with IMU_GYRO by seq. Each half waits in a buffer of SF_IMU_HALVES, so two
 * swapped frames (ACCEL n, ACCEL n+1, GYRO n, GYRO n+1) still pair. */
static int on_imu_half(sf_board_rx_t *const rx, const bool is_accel, const sf_imu_half_t *const half,
                       sf_rx_event_t *const ev)
{
    sf_imu_half_t *const mine = is_accel ? rx->accel : rx->gyro;
    sf_imu_half_t *const other = is_accel ? rx->gyro : rx->accel;
    bool repeats = rx->imu_time.started && rx->imu_time.epoch == rx->clock.restarts && rx->imu_time.last_seq == half->seq;
    int match = -1;
    for (int i = 0; i < SF_IMU_HALVES; i++) {
        repeats = repeats || (mine[i].valid && mine[i].seq == half->seq && mine[i].t_lo_ms == half->t_lo_ms);
        if (other[i].valid && other[i].seq == half->seq) {
            match = i;
        }
    }
    if (repeats) {
        rx->counters.duplicates++; /* the same half again (the bus repeated a frame) */
        return SF_EDUPLICATE;
    }
    if (match >= 0) {
        const sf_imu_half_t partner = other[match];
        other[match].valid = false;
        drop_older(rx, mine, half->seq);
        drop_older(rx, other, half->seq);
        const sf_imu_half_t *const acc = is_accel ? half : &partner;
        const sf_imu_half_t *const gyr = is_accel ? &partner : half;
        sf_rx_imu_t *const out = &ev->u.imu;
        const int rc = resolve(rx, &rx->imu_time, half->seq, half->t_lo_ms, &out->t_us, &out->seq);
        if (rc != SF_OK) {
            return rc;
        }
        for (int i = 0; i < 3; i++) {
            out->accel_mps2[i] = acc->xyz[i];
            out->gyro_radps[i] = gyr->xyz[i] * DEG_TO_RAD;
        }
        ev->kind = sf_rx_imu;
        return 1;
    }
    int slot = 0; /* a free slot, else the oldest half (its partner was lost) */
    for (int i = 0; i < SF_IMU_HALVES; i++) {
        if (!mine[i].valid) {
            slot = i;
            break;
        }
        if ((int8_t)(uint8_t)(mine[slot].seq - mine[i].seq) > 0) {
            slot = i;
        }
    }
    if (mine[slot].valid) {
        rx->counters.imu_unpaired++;
    }
    mine[slot] = *half;
    mine[slot].valid = true;
    return 0;
}

/* The full board time a GNSS_INFO carries, unwrapped (sf_board_clock_carried); a corrupt one is
 * counted as a decode error. */
static int carried_time(sf_board_rx_t *const rx, const uint32_t time_ms, int64_t *const t_ms)
{
    const int rc = sf_board_clock_carried(&rx->clock, time_ms, rx->host_t_us, t_ms);
    if (rc == SF_ENOTSYNC) {
        rx->counters.unsynced++;
    } else if (rc == SF_ERANGE) {
        rx->counters.decode_errors++;
    }
    return rc;
}

/* ---- one handler per board.dbc frame ------------------------------------------------------------ */

static int on_board_time(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_board_time_t m;
    (void)board_board_time_unpack(&m, f->data, f->dlc);
    /* a restart: see sf_board_rx_frame; output time goes on across it, so the BLE window's does too */
    if (sf_board_clock_on_time(&rx->clock, m.time_ms, m.boot_id, f->host_t_us) == sf_board_time_held) {
        return 0;
    }
    return sf_board_ble_tick(rx, sf_board_clock_output_us(&rx->clock, rx->clock.board_ms), ev);
}

static int on_imu_accel(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_imu_accel_t m;
    (void)board_imu_accel_unpack(&m, f->data, f->dlc);
    const sf_imu_half_t h = {true, m.seq, m.t_lo_ms,
                             {board_imu_accel_accel_x_decode(m.accel_x), board_imu_accel_accel_y_decode(m.accel_y),
                              board_imu_accel_accel_z_decode(m.accel_z)}};
    return on_imu_half(rx, true, &h, ev);
}

static int on_imu_gyro(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_imu_gyro_t m;
    (void)board_imu_gyro_unpack(&m, f->data, f->dlc);
    const sf_imu_half_t h = {true, m.seq, m.t_lo_ms,
                             {board_imu_gyro_gyro_x_decode(m.gyro_x), board_imu_gyro_gyro_y_decode(m.gyro_y),
                              board_imu_gyro_gyro_z_decode(m.gyro_z)}};
    return on_imu_half(rx, false, &h, ev);
}

static int on_mag(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_mag_t m;
    (void)board_mag_unpack(&m, f->data, f->dlc);
    sf_rx_mag_t *const out = &ev->u.mag;
    const int rc = resolve(rx, &rx->mag_time, m.seq, m.t_lo_ms, &out->t_us, &out->seq);
    if (rc != SF_OK) {
        return rc;
    }
    out->field_ut[0] = board_mag_mag_x_decode(m.mag_x);
    out->field_ut[1] = board_mag_mag_y_decode(m.mag_y);
    out->field_ut[2] = board_mag_mag_z_decode(m.mag_z);
    ev->kind = sf_rx_mag;
    return 1;
}

static int on_baro(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_baro_t m;
    (void)board_baro_unpack(&m, f->data, f->dlc);
    if (!board_baro_pressure_is_in_range(m.pressure)) {
        rx->counters.decode_errors++;
        return SF_ERANGE;
    }
    sf_rx_baro_t *const out = &ev->u.baro;
    const int rc = resolve(rx, &rx->baro_time, m.seq, m.t_lo_ms, &out->t_us, &out->seq);
    if (rc != SF_OK) {
        return rc;
    }
    out->pressure_pa = board_baro_pressure_decode(m.pressure);
    out->temperature_degc = board_baro_temperature_decode(m.temperature);
    ev->kind = sf_rx_baro;
    return 1;
}

static int on_wifi_scan_begin(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_wifi_scan_begin_t m;
    (void)board_wifi_scan_begin_unpack(&m, f->data, f->dlc);
    return sf_board_scan_begin(&rx->scan, &rx->counters, &rx->clock, rx->host_t_us, &m, ev);
}

static int on_wifi_ap(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    (void)ev;
    struct board_wifi_ap_t m;
    (void)board_wifi_ap_unpack(&m, f->data, f->dlc);
    return sf_board_scan_ap(&rx->scan, &rx->counters, &m);
}

static int on_wifi_scan_end(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_wifi_scan_end_t m;
    (void)board_wifi_scan_end_unpack(&m, f->data, f->dlc);
    return sf_board_scan_end(&rx->scan, &rx->counters, &m, ev);
}

static int on_gnss_info(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    (void)ev;
    struct board_gnss_info_t m;
    (void)board_gnss_info_unpack(&m, f->data, f->dlc);
    int64_t t_ms;
    const int rc = carried_time(rx, m.time_ms, &t_ms);
    if (rc != SF_OK) {
        return rc;
    }
    rx->gnss_info_valid = true;
    rx->gnss_t_ms = t_ms;
    rx->gnss_alt_m = board_gnss_info_altitude_decode(m.altitude);
    rx->gnss_accuracy_m = (float)board_gnss_info_accuracy_decode(m.accuracy);
    return 0;
}

static int on_gnss_position(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_gnss_position_t m;
    (void)board_gnss_position_unpack(&m, f->data, f->dlc);
    if (!rx->gnss_info_valid || !board_gnss_position_latitude_is_in_range(m.latitude) ||
        !board_gnss_position_longitude_is_in_range(m.longitude)) {
        rx->gnss_info_valid = false;
        rx->counters.decode_errors++;
        return SF_ERANGE;
    }
    rx->gnss_info_valid = false;
    sf_rx_gnss_t *const out = &ev->u.gnss;
    out->t_us = sf_board_clock_output_us(&rx->clock, rx->gnss_t_ms);
    out->lat_deg = board_gnss_position_latitude_decode(m.latitude);
    out->lon_deg = board_gnss_position_longitude_decode(m.longitude);
    out->alt_m = rx->gnss_alt_m;
    out->accuracy_m = rx->gnss_accuracy_m;
    ev->kind = sf_rx_gnss;
    return 1;
}

static int on_ble_adv(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_ble_adv_t m;
    (void)board_ble_adv_unpack(&m, f->data, f->dlc);
    return sf_board_ble_adv(rx, &m, ev);
}

static int on_landmark(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    struct board_landmark_t m;
    (void)board_landmark_unpack(&m, f->data, f->dlc);
    if (!board_landmark_x_is_in_range(m.x) || !board_landmark_y_is_in_range(m.y) ||
        !board_landmark_floor_is_in_range(m.floor)) {
        rx->counters.decode_errors++;
        return SF_ERANGE;
    }
    int64_t t_ms;
    if (sf_board_clock_event(&rx->clock, m.t_lo_ms, rx->host_t_us, &t_ms) != SF_OK) {
        rx->counters.unsynced++;
        return SF_ENOTSYNC;
    }
    sf_rx_landmark_t *const out = &ev->u.landmark;
    out->t_us = sf_board_clock_output_us(&rx->clock, t_ms);
    out->landmark_id = 0;
    out->x_m = board_landmark_x_decode(m.x);
    out->y_m = board_landmark_y_decode(m.y);
    out->floor = (int16_t)board_landmark_floor_decode(m.floor);
    out->accuracy_m = rx->landmark_accuracy_m;
    ev->kind = sf_rx_landmark;
    return 1;
}

static int on_board_status(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    (void)ev;
    struct board_board_status_t m;
    (void)board_board_status_unpack(&m, f->data, f->dlc);
    rx->counters.board_status++;
    rx->counters.board_tx_overflows = m.tx_overflows;
    return 0;
}

/* ---- the frame table: id, DBC length, handler ------------------------------------------------------
 * Adding a frame: its BO_ in board.dbc (cantools generates board_<name>_unpack and the constants) and
 * one row here with its handler; a frame that carries a new kind of sample also adds that kind to
 * SF_RX_KINDS (sf_rx_event.h), which the LCM replay and the daemon then cannot miss. */

typedef int (*frame_handler_t)(sf_board_rx_t *rx, const sf_can_frame_t *f, sf_rx_event_t *ev);

typedef struct {
    uint32_t id;
    unsigned length; /* bytes the DBC declares */
    frame_handler_t on_frame;
} frame_row_t;

static const frame_row_t frame_rows[] = {
    {BOARD_BOARD_TIME_FRAME_ID, BOARD_BOARD_TIME_LENGTH, on_board_time},
    {BOARD_IMU_ACCEL_FRAME_ID, BOARD_IMU_ACCEL_LENGTH, on_imu_accel},
    {BOARD_IMU_GYRO_FRAME_ID, BOARD_IMU_GYRO_LENGTH, on_imu_gyro},
    {BOARD_MAG_FRAME_ID, BOARD_MAG_LENGTH, on_mag},
    {BOARD_BARO_FRAME_ID, BOARD_BARO_LENGTH, on_baro},
    {BOARD_WIFI_SCAN_BEGIN_FRAME_ID, BOARD_WIFI_SCAN_BEGIN_LENGTH, on_wifi_scan_begin},
    {BOARD_WIFI_AP_FRAME_ID, BOARD_WIFI_AP_LENGTH, on_wifi_ap},
    {BOARD_WIFI_SCAN_END_FRAME_ID, BOARD_WIFI_SCAN_END_LENGTH, on_wifi_scan_end},
    {BOARD_GNSS_POSITION_FRAME_ID, BOARD_GNSS_POSITION_LENGTH, on_gnss_position},
    {BOARD_GNSS_INFO_FRAME_ID, BOARD_GNSS_INFO_LENGTH, on_gnss_info},
    {BOARD_BLE_ADV_FRAME_ID, BOARD_BLE_ADV_LENGTH, on_ble_adv},
    {BOARD_LANDMARK_FRAME_ID, BOARD_LANDMARK_LENGTH, on_landmark},
    {BOARD_BOARD_STATUS_FRAME_ID, BOARD_BOARD_STATUS_LENGTH, on_board_status},
};

/* The row of a standard data frame's id, or NULL. */
static const frame_row_t *find_row(const sf_can_frame_t *const f)
{
    if (f->extended || f->remote) {
        return NULL;
    }
    for (size_t i = 0; i < sizeof frame_rows / sizeof frame_rows[0]; i++) {
        if (frame_rows[i].id == f->id) {
            return &frame_rows[i];
        }
    }
    return NULL;
}

unsigned sf_board_rx_dbc_length(const uint32_t id)
{
    const sf_can_frame_t f = {.id = id};
    const frame_row_t *const row = find_row(&f);
    return row != NULL ? row->length : 0u;
}

int sf_board_rx_frame(sf_board_rx_t *const rx, const sf_can_frame_t *const f, sf_rx_event_t *const ev)
{
    rx->counters.frames++;
    ev->kind = sf_rx_none;
    if (rx->counters.frames > 1 && f->host_t_us - rx->host_t_us > SILENCE_US) {
        rx->counters.silences++;
    }
    rx->host_t_us = f->host_t_us;
    const frame_row_t *const row = find_row(f);
    if (row == NULL) {
        rx->counters.unknown_id++;
        return SF_EUNKNOWN_ID;
    }
    if (f->dlc < row->length) {
        rx->counters.bad_length++;
        return SF_ELENGTH;
    }
    const int rc = row->on_frame(rx, f, ev);
    if (rx->counters.board_restarts != rx->clock.restarts) {
        on_new_epoch(rx); /* a BOARD_TIME, or a restarted stream's first sample, confirmed a restart */
        rx->counters.board_restarts = rx->clock.restarts;
    }
    /* the clock's own counts (a held BOARD_TIME is rejected when it is never confirmed) */
    rx->counters.board_time_rejected = rx->clock.time_rejected;
    rx->counters.board_time_jumps = rx->clock.time_jumps;
    if (rc >= 0) {
        rx->counters.frames_ok++;
    }
    if (rc == 1) {
        sf_rx_count_sample(&rx->counters, ev->kind);
    }
    return rc;
}

void sf_rx_count_sample(sf_rx_counters_t *const c, const sf_rx_kind_t kind)
{
    switch (kind) { /* no default: a new kind needs its counter (-Wswitch) */
    case sf_rx_imu: c->imu++; break;
    case sf_rx_mag: c->mag++; break;
    case sf_rx_baro: c->baro++; break;
    case sf_rx_wifi: c->wifi++; break;
    case sf_rx_gnss: c->gnss++; break;
    case sf_rx_ble: c->ble++; break;
    case sf_rx_landmark: c->landmark++; break;
    case sf_rx_none: break;
    }
}
