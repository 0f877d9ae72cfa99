/* sf_test_frames.h — board frames for the tests, packed by the C that cantools generates from
 * firmware/board.dbc (never by hand, so the tests follow the DBC). Header-only; values are physical
 * (m/s², deg/s, ...) and are rounded to the nearest raw value with the generated *_decode scale.
 * (The generated *_encode functions truncate toward zero: 10 deg/s would become 9.95 deg/s.) */
#ifndef SF_TEST_FRAMES_H
#define SF_TEST_FRAMES_H

#include <stdint.h>
#include <string.h>

#include "board.h"
#include "sf_can_frame.h"

#include <math.h>

/* The raw value of signal sig of message msg nearest to the physical value v (a long long: callers
 * cast it to the signal's field type, explicitly, for -Wconversion). */
#define TF_RAW(msg, sig, v)                                                                                 \
    llround(((v) - board_##msg##_##sig##_decode(0)) /                                                      \
            (board_##msg##_##sig##_decode(1) - board_##msg##_##sig##_decode(0)))

/* A classic 8-byte frame with id; data filled by the caller. */
static inline sf_can_frame_t tf_frame(const uint32_t id)
{
    sf_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.dlc = 8;
    return f;
}

static inline sf_can_frame_t tf_board_time(const uint32_t time_ms, const uint8_t boot_id)
{
    sf_can_frame_t f = tf_frame(BOARD_BOARD_TIME_FRAME_ID);
    const struct board_board_time_t m = {.time_ms = time_ms, .boot_id = boot_id};
    (void)board_board_time_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_accel(const uint8_t seq, const uint8_t t_lo_ms, const double x, const double y,
                                      const double z)
{
    sf_can_frame_t f = tf_frame(BOARD_IMU_ACCEL_FRAME_ID);
    const struct board_imu_accel_t m = {.accel_x = (int16_t)TF_RAW(imu_accel, accel_x, x),
                                        .accel_y = (int16_t)TF_RAW(imu_accel, accel_y, y),
                                        .accel_z = (int16_t)TF_RAW(imu_accel, accel_z, z),
                                        .seq = seq,
                                        .t_lo_ms = t_lo_ms};
    (void)board_imu_accel_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_gyro(const uint8_t seq, const uint8_t t_lo_ms, const double x_dps,
                                     const double y_dps, const double z_dps)
{
    sf_can_frame_t f = tf_frame(BOARD_IMU_GYRO_FRAME_ID);
    const struct board_imu_gyro_t m = {.gyro_x = (int16_t)TF_RAW(imu_gyro, gyro_x, x_dps),
                                       .gyro_y = (int16_t)TF_RAW(imu_gyro, gyro_y, y_dps),
                                       .gyro_z = (int16_t)TF_RAW(imu_gyro, gyro_z, z_dps),
                                       .seq = seq,
                                       .t_lo_ms = t_lo_ms};
    (void)board_imu_gyro_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_mag(const uint8_t seq, const uint8_t t_lo_ms, const double x, const double y,
                                    const double z)
{
    sf_can_frame_t f = tf_frame(BOARD_MAG_FRAME_ID);
    const struct board_mag_t m = {.mag_x = (int16_t)TF_RAW(mag, mag_x, x),
                                  .mag_y = (int16_t)TF_RAW(mag, mag_y, y),
                                  .mag_z = (int16_t)TF_RAW(mag, mag_z, z),
                                  .seq = seq,
                                  .t_lo_ms = t_lo_ms};
    (void)board_mag_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_scan_begin(const uint8_t scan_id, const uint32_t time_ms)
{
    sf_can_frame_t f = tf_frame(BOARD_WIFI_SCAN_BEGIN_FRAME_ID);
    const struct board_wifi_scan_begin_t m = {.scan_id = scan_id, .time_ms = time_ms};
    (void)board_wifi_scan_begin_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_scan_ap(const uint64_t bssid, const int8_t rssi, const uint8_t channel)
{
    sf_can_frame_t f = tf_frame(BOARD_WIFI_AP_FRAME_ID);
    const struct board_wifi_ap_t m = {.bssid = bssid, .rssi = rssi, .channel = channel};
    (void)board_wifi_ap_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_scan_end(const uint8_t scan_id, const uint8_t n_ap)
{
    sf_can_frame_t f = tf_frame(BOARD_WIFI_SCAN_END_FRAME_ID);
    const struct board_wifi_scan_end_t m = {.scan_id = scan_id, .n_ap = n_ap};
    (void)board_wifi_scan_end_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_gnss_info(const uint32_t time_ms, const double alt_m, const double accuracy_m)
{
    sf_can_frame_t f = tf_frame(BOARD_GNSS_INFO_FRAME_ID);
    const struct board_gnss_info_t m = {.time_ms = time_ms,
                                        .altitude = (int32_t)TF_RAW(gnss_info, altitude, alt_m),
                                        .accuracy = (uint16_t)TF_RAW(gnss_info, accuracy, accuracy_m)};
    (void)board_gnss_info_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_gnss_position(const double lat_deg, const double lon_deg)
{
    sf_can_frame_t f = tf_frame(BOARD_GNSS_POSITION_FRAME_ID);
    const struct board_gnss_position_t m = {.latitude = (int32_t)TF_RAW(gnss_position, latitude, lat_deg),
                                            .longitude = (int32_t)TF_RAW(gnss_position, longitude, lon_deg)};
    (void)board_gnss_position_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_ble_adv(const uint64_t beacon_id, const int8_t rssi_dbm, const uint8_t t_lo_ms)
{
    sf_can_frame_t f = tf_frame(BOARD_BLE_ADV_FRAME_ID);
    const struct board_ble_adv_t m = {.beacon_id = beacon_id, .rssi = rssi_dbm, .t_lo_ms = t_lo_ms};
    (void)board_ble_adv_pack(f.data, &m, sizeof f.data);
    return f;
}

static inline sf_can_frame_t tf_landmark(const double x_m, const double y_m, const int8_t floor, const uint8_t t_lo_ms)
{
    sf_can_frame_t f = tf_frame(BOARD_LANDMARK_FRAME_ID);
    const struct board_landmark_t m = {.x = (int32_t)TF_RAW(landmark, x, x_m),
                                       .y = (int32_t)TF_RAW(landmark, y, y_m),
                                       .floor = floor,
                                       .t_lo_ms = t_lo_ms};
    (void)board_landmark_pack(f.data, &m, sizeof f.data);
    return f;
}

#endif
