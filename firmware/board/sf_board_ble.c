/* sf_board_ble.c — BLE scan windows for sf_board_rx (see sf_board_ble.h, rules in sf_board_rx.h). */
#include "sf_board_ble.h"

#include <string.h>

#include "sf_error.h"

int sf_board_ble_close(sf_board_rx_t *const rx, sf_rx_event_t *const ev)
{
    sf_ble_window_t *const w = &rx->ble;
    if (!w->open) {
        return 0;
    }
    w->open = false;
    w->floor_us = w->scan.t_us + rx->ble_window_us;
    ev->kind = sf_rx_ble;
    ev->u.ble = w->scan;
    return 1;
}

int sf_board_ble_tick(sf_board_rx_t *const rx, const int64_t now_us, sf_rx_event_t *const ev)
{
    const sf_ble_window_t *const w = &rx->ble;
    if (w->open && now_us >= w->scan.t_us + rx->ble_window_us) {
        return sf_board_ble_close(rx, ev);
    }
    return 0;
}

static void open_window(sf_ble_window_t *const w, const int64_t t_us)
{
    w->open = true;
    w->floor_us = t_us;
    w->scan.t_us = t_us;
    w->scan.n = 0;
}

/* The beacon's slot in the open window, or -1. */
static int32_t slot_of(const sf_ble_window_t *const w, const int64_t beacon_id)
{
    for (int32_t i = 0; i < w->scan.n; i++) {
        if (w->scan.beacon_id[i] == beacon_id) {
            return i;
        }
    }
    return -1;
}

int sf_board_ble_adv(sf_board_rx_t *const rx, const struct board_ble_adv_t *const m, sf_rx_event_t *const ev)
{
    if (m->beacon_id == 0 || m->rssi >= 0) { /* no advertiser has MAC 0; a received level is below 0 dBm */
        rx->counters.decode_errors++;
        return SF_ERANGE;
    }
    int64_t t_ms;
    if (sf_board_clock_event(&rx->clock, m->t_lo_ms, rx->host_t_us, &t_ms) != SF_OK) {
        rx->counters.unsynced++;
        return SF_ENOTSYNC;
    }
    const int64_t t_us = sf_board_clock_output_us(&rx->clock, t_ms);
    sf_ble_window_t *const w = &rx->ble;
    if (t_us < w->floor_us) {
        rx->counters.late++;
        return SF_ELATE;
    }
    const int64_t id = (int64_t)m->beacon_id;
    int32_t i = w->open ? slot_of(w, id) : -1;
    if (i >= 0 && w->last_us[i] == t_us) {
        rx->counters.duplicates++;
        return SF_EDUPLICATE;
    }
    int result = 0;
    if (w->open && t_us >= w->scan.t_us + rx->ble_window_us) {
        result = sf_board_ble_close(rx, ev);
        i = -1;
    }
    if (!w->open) {
        open_window(w, t_us);
    }
    if (i < 0) {
        if (w->scan.n >= SF_BLE_MAX_BEACONS) {
            rx->counters.ble_dropped++;
            return SF_EFULL;
        }
        i = w->scan.n++;
        w->scan.beacon_id[i] = id;
        w->scan.rssi_dbm[i] = 0.0f;
        w->heard[i] = 0;
    }
    if (w->heard[i] < UINT16_MAX) {
        w->heard[i]++;
    }
    w->scan.rssi_dbm[i] += ((float)m->rssi - w->scan.rssi_dbm[i]) / (float)w->heard[i]; /* running mean */
    w->last_us[i] = t_us;
    rx->counters.ble_adverts++;
    return result;
}
