/* sf_rx_event.h — the one tagged sensor sample that every input produces: the CAN decoder
 * (sf_board_rx.h) and the raw-sensor LCM replay (sf_lcm_input.h) both fill an sf_rx_event_t, and the
 * daemon feeds the estimator from it in one switch.
 *
 * SF_RX_KINDS is the single list of sample kinds, each with the LCM channel that carries it. From it
 * come the kind enum, the union and the LCM codec table (sf_rx_lcm.c), which needs a decode_<kind> and
 * an encode_<kind> for every row or does not compile; the daemon's switch has no default, so -Wswitch
 * (-Werror) stops a build that forgets a kind. A replay therefore cannot silently ignore a kind the
 * CAN path produces.
 *
 * Units are in the names; times are board time [µs]. Memory: sizeof(sf_rx_event_t) = 4112 B on
 * x86-64 (a full Wi-Fi scan of SF_WIFI_MAX_AP access points; asserted ≤ 4200 B). */
#ifndef SF_RX_EVENT_H
#define SF_RX_EVENT_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_channels.h"

#define SF_WIFI_MAX_AP 255 /* WIFI_SCAN_END.n_ap is 8 bits */
/* Distinct beacons of one BLE scan window: msindoor site1/F2's phones heard at most 20 distinct
 * beacons in one second (264 on the floor), the gsd trials 6 in all; a window's beacons beyond this
 * are counted (ble_dropped) and dropped. */
#define SF_BLE_MAX_BEACONS 32

/*              kind  LCM channel (lcmtypes/channels.csv, generated sf_channels.h) */
#define SF_RX_KINDS(X)        \
    X(imu,  SF_CHANNEL_IMU)   \
    X(mag,  SF_CHANNEL_MAG)   \
    X(baro, SF_CHANNEL_BARO)  \
    X(wifi, SF_CHANNEL_WIFI)  \
    X(gnss, SF_CHANNEL_GNSS)  \
    X(ble,  SF_CHANNEL_BLE)   \
    X(landmark, SF_CHANNEL_LANDMARK)

typedef enum {
    sf_rx_none = 0,
#define SF_RX_KIND_ENUM(kind, channel) sf_rx_##kind,
    SF_RX_KINDS(SF_RX_KIND_ENUM)
#undef SF_RX_KIND_ENUM
} sf_rx_kind_t;

/* Number of kinds (sf_rx_none not counted; kinds are 1 .. SF_RX_KIND_COUNT). */
#define SF_RX_KIND_ONE(kind, channel) +1
enum { SF_RX_KIND_COUNT = 0 SF_RX_KINDS(SF_RX_KIND_ONE) };
#undef SF_RX_KIND_ONE

typedef struct {
    int64_t t_us;
    int64_t seq;
    double accel_mps2[3];
    double gyro_radps[3];
} sf_rx_imu_t;

typedef struct {
    int64_t t_us;
    int64_t seq;
    double field_ut[3];
} sf_rx_mag_t;

typedef struct {
    int64_t t_us;
    int64_t seq;
    double pressure_pa;
    double temperature_degc;
} sf_rx_baro_t;

typedef struct {
    int64_t t_us;
    int64_t scan_id;
    bool complete;
    int32_t n_ap;
    int64_t bssid[SF_WIFI_MAX_AP];
    float rssi_dbm[SF_WIFI_MAX_AP];
    int32_t freq_mhz[SF_WIFI_MAX_AP];
} sf_rx_wifi_t;

typedef struct {
    int64_t t_us;
    double lat_deg;
    double lon_deg;
    double alt_m;
    float accuracy_m;
} sf_rx_gnss_t;

/* One BLE scan window (ble_scan_t): each beacon once, its RSSI the mean in dBm of the window's
 * advertisements from it. */
typedef struct {
    int64_t t_us; /* the window's first advertisement */
    int32_t n;
    int64_t beacon_id[SF_BLE_MAX_BEACONS]; /* 48-bit MAC */
    float rssi_dbm[SF_BLE_MAX_BEACONS];
} sf_rx_ble_t;

/* One landmark event (landmark_t). */
typedef struct {
    int64_t t_us;
    int32_t landmark_id; /* 0: unknown (the LANDMARK frame carries none) */
    double x_m;
    double y_m;
    int16_t floor;
    float accuracy_m; /* 1 sigma */
} sf_rx_landmark_t;

typedef struct {
    sf_rx_kind_t kind;
    union {
#define SF_RX_KIND_MEMBER(kind, channel) sf_rx_##kind##_t kind;
        SF_RX_KINDS(SF_RX_KIND_MEMBER)
#undef SF_RX_KIND_MEMBER
    } u;
} sf_rx_event_t;

_Static_assert(sizeof(sf_rx_event_t) <= 4200, "sf_rx_event.h promises at most 4200 B");

#endif
