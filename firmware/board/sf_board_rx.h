/* sf_board_rx.h — board frames in, timed sensor samples out.
 *
 * Decodes each frame with the pack/unpack code that cantools generates from firmware/board.dbc,
 * gives every sample its board time (sf_board_time.h), pairs IMU_ACCEL with IMU_GYRO by seq,
 * reassembles Wi-Fi scans from SCAN_BEGIN / AP / SCAN_END (sf_board_scan.c), pairs GNSS_INFO with
 * GNSS_POSITION, groups BLE_ADV advertisements into one scan per window (sf_board_ble.c) and makes a
 * LANDMARK frame one landmark event.
 *
 * BLE and landmark frames carry t_lo_ms but no seq: their time is the one with those low bits nearest
 * to the clock (sf_board_clock_event). A BLE window starts at its first advertisement and spans
 * ble.window_ms of board time (sf_params.h); it closes when an advertisement past it arrives (which
 * opens the next) or when a believed BOARD_TIME is past it, never on a host clock; at the end of the
 * input sf_board_rx_flush hands back the open one. A beacon heard several times in one window is
 * averaged in dBm: its advertisements fade independently (several dB each, 20-100 ms apart), so the
 * mean of n is a steadier level for a path-loss range than the latest alone. The same beacon at the
 * same millisecond again is the bus repeating a frame (a beacon advertises at most every 20 ms, BLE
 * spec): a duplicate. An advertisement older than the open window (or, with none open, the last closed
 * one's end) arrived late and is skipped; a window's beacons beyond SF_BLE_MAX_BEACONS are counted in
 * ble_dropped. A LANDMARK's accuracy is landmark.accuracy_m (the frame has none), its id 0.
 * One frame yields at most one event (sf_rx_event.h). Frames are dispatched through one table in
 * sf_board_rx.c (id, DBC length, handler): adding a frame is its DBC entry plus one row. Bad frames
 * are counted in sf_rx_counters_t and skipped: the return code says which counter moved, so the
 * caller can print a message naming the line.
 *
 * Memory: sizeof(sf_board_rx_t) = 5544 B on x86-64 (one Wi-Fi scan and one BLE window in progress;
 * asserted ≤ 5.5 KiB); no heap. */
#ifndef SF_BOARD_RX_H
#define SF_BOARD_RX_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_board_scan.h"
#include "sf_board_time.h"
#include "sf_can_frame.h"
#include "sf_params.h"
#include "sf_rx_event.h"

/* Counters never decrease. (Tagged: sf_board_scan.h counts into it by a pointer.) */
typedef struct sf_rx_counters {
    uint64_t frames;          /* frames offered */
    uint64_t frames_ok;       /* decoded and used */
    uint64_t unknown_id;      /* id not in the DBC, extended or remote frames */
    uint64_t bad_length;      /* shorter than the DBC length */
    uint64_t decode_errors;   /* out-of-range signal, orphan AP or GNSS half, bad channel */
    uint64_t seq_gaps;        /* samples missing by sequence, all streams */
    uint64_t unsynced;        /* samples before the first BOARD_TIME */
    uint64_t duplicates;      /* repeated seq */
    uint64_t imu_unpaired;    /* IMU halves whose other half never came */
    uint64_t wifi_incomplete; /* scans with lost AP frames or without SCAN_END */
    uint64_t imu;
    uint64_t mag;
    uint64_t baro;
    uint64_t wifi;
    uint64_t gnss;
    uint64_t ble;             /* BLE scan windows handed out */
    uint64_t landmark;        /* landmark events */
    uint64_t ble_adverts;     /* BLE advertisements used (averaged into a window) */
    uint64_t ble_dropped;     /* advertisements of beacons beyond a window's SF_BLE_MAX_BEACONS */
    uint64_t late;            /* samples that arrived after a newer one (reordered), skipped */
    uint64_t seq_rejected;    /* samples whose seq claims more time than passed (corrupt), skipped */
    uint64_t silences;        /* gaps of more than 1 s without any frame */
    uint64_t board_time_rejected; /* BOARD_TIME frames not believed (never confirmed) */
    uint64_t board_time_jumps;    /* same boot, board time jumped forwards (confirmed) */
    uint64_t board_status;
    uint64_t board_restarts;  /* board restarts: new boot id or time gone back (confirmed) */
    uint64_t board_tx_overflows; /* last value the board reported */
} sf_rx_counters_t;

typedef struct {
    bool valid;
    uint8_t seq;
    uint8_t t_lo_ms;
    double xyz[3];
} sf_imu_half_t;

#define SF_IMU_HALVES 2

/* The BLE scan window in progress (sf_board_ble.c). Times are output times [µs]. */
typedef struct {
    bool open;
    int64_t floor_us;                      /* advertisements before this are late */
    uint16_t heard[SF_BLE_MAX_BEACONS];    /* advertisements averaged, per beacon */
    int64_t last_us[SF_BLE_MAX_BEACONS];   /* per beacon: its latest advertisement */
    sf_rx_ble_t scan;                      /* rssi_dbm holds the running mean */
} sf_ble_window_t;

typedef struct {
    sf_board_clock_t clock;
    sf_stream_time_t imu_time;
    sf_stream_time_t mag_time;
    sf_stream_time_t baro_time;
    sf_imu_half_t accel[SF_IMU_HALVES]; /* halves waiting for their partner */
    sf_imu_half_t gyro[SF_IMU_HALVES];
    int64_t host_t_us;    /* host receive time of the latest frame */
    sf_board_scan_t scan; /* the Wi-Fi scan in reassembly (sf_board_scan.h) */
    bool gnss_info_valid;
    int64_t gnss_t_ms;
    double gnss_alt_m;
    float gnss_accuracy_m;
    sf_ble_window_t ble;
    int64_t ble_window_us;      /* ble.window_ms */
    float landmark_accuracy_m;  /* landmark.accuracy_m */
    sf_rx_counters_t counters;
} sf_board_rx_t;

_Static_assert(sizeof(sf_board_rx_t) <= 5632, "sf_board_rx.h promises at most 5.5 KiB");

/* Starts the decoder with the params table's defaults for ble.window_ms and landmark.accuracy_m. */
void sf_board_rx_init(sf_board_rx_t *rx);

/* Takes ble.window_ms and landmark.accuracy_m from p (before the first frame). */
void sf_board_rx_configure(sf_board_rx_t *rx, const sf_params_t *p);

/* Consumes one frame. Returns 1 when *event was filled (a SCAN_BEGIN that finds a scan still open
 * returns that scan, marked incomplete), 0 when the frame was used without an event, or a negative
 * code when the frame was skipped and counted: SF_EUNKNOWN_ID, SF_ELENGTH, SF_ERANGE (decode error,
 * or a carried time far from the clock), SF_ENOTSYNC (no board time yet), SF_EDUPLICATE (a repeated
 * frame: IMU half, sample, scan, AP, SCAN_END or BLE advertisement), SF_ELATE (reordered), SF_ESEQ
 * (corrupt seq), SF_EFULL (a BLE window already full: ble_dropped). A BLE_ADV past the open window
 * returns that window (1) and opens the next with itself; a BOARD_TIME past it returns it too.
 * Sample times are output times (sf_board_time.h): continuous across board restarts. */
int sf_board_rx_frame(sf_board_rx_t *rx, const sf_can_frame_t *frame, sf_rx_event_t *event);

/* At the end of the input: 1 with the open BLE window in *event (closed), else 0. */
int sf_board_rx_flush(sf_board_rx_t *rx, sf_rx_event_t *event);

/* Counts one sample of a kind in its counter (imu .. landmark; sf_rx_none counts nothing): the one place
 * for both input paths (sf_board_rx_frame, and the LCM replay in sf_input). */
void sf_rx_count_sample(sf_rx_counters_t *counters, sf_rx_kind_t kind);

/* The length board.dbc declares for a standard frame id [bytes]; 0 for an id not in board.dbc. */
unsigned sf_board_rx_dbc_length(uint32_t id);

#endif
