/* sf_board_scan.c — Wi-Fi scan reassembly for sf_board_rx (see sf_board_scan.h). */
#include "sf_board_scan.h"

#include "sf_error.h"

/* Closes the open scan into *ev. */
static int close_scan(sf_board_rx_t *const rx, const bool complete, sf_rx_event_t *const ev)
{
    rx->scan_open = false;
    rx->last_scan_valid = true;
    rx->last_scan_raw_id = rx->scan_raw_id;
    rx->last_scan_time_ms = rx->scan_time_ms;
    if (!rx->scan_timed) {
        return 0; /* started before the first BOARD_TIME: already counted as unsynced */
    }
    rx->scan.complete = complete;
    if (!complete) {
        rx->counters.wifi_incomplete++;
    }
    ev->kind = sf_rx_wifi;
    ev->u.wifi = rx->scan;
    return 1;
}

int sf_board_scan_begin(sf_board_rx_t *const rx, const struct board_wifi_scan_begin_t *const m,
                        sf_rx_event_t *const ev)
{
    const bool repeats = rx->scan_open ? rx->scan_raw_id == m->scan_id && rx->scan_time_ms == m->time_ms
                                       : rx->last_scan_valid && rx->last_scan_raw_id == m->scan_id &&
                                             rx->last_scan_time_ms == m->time_ms;
    if (repeats) {
        rx->counters.duplicates++; /* a scan repeated: its frames are dropped until the next scan */
        rx->scan_repeat = !rx->scan_open;
        return SF_EDUPLICATE;
    }
    rx->scan_repeat = false;
    int result = 0;
    if (rx->scan_open) {
        result = close_scan(rx, false, ev); /* SCAN_END was lost */
    }
    int64_t t_ms;
    const int rc = sf_board_rx_carried_time(rx, m->time_ms, &t_ms);
    if (rc == SF_ERANGE) {
        return result != 0 ? result : rc; /* no scan opens: its APs count as orphans */
    }
    rx->scan_open = true;
    rx->scan_raw_id = m->scan_id;
    rx->scan_time_ms = m->time_ms;
    rx->scan_timed = rc == SF_OK;
    if (!rx->scan_timed) {
        return result != 0 ? result : SF_ENOTSYNC;
    }
    rx->scan_id = rx->scan_id_started ? rx->scan_id + (uint8_t)(m->scan_id - (uint8_t)rx->scan_id) : m->scan_id;
    rx->scan_id_started = true;
    rx->scan.t_us = sf_board_clock_output_us(&rx->clock, t_ms);
    rx->scan.scan_id = rx->scan_id;
    rx->scan.n_ap = 0;
    return result;
}

int sf_board_scan_ap(sf_board_rx_t *const rx, const struct board_wifi_ap_t *const m)
{
    if (rx->scan_repeat) {
        return SF_EDUPLICATE; /* counted once, at its SCAN_BEGIN */
    }
    for (int32_t i = 0; rx->scan_open && i < rx->scan.n_ap; i++) {
        if (rx->scan.bssid[i] == (int64_t)m->bssid) {
            rx->counters.duplicates++; /* a scan lists each BSSID once */
            return SF_EDUPLICATE;
        }
    }
    const int32_t mhz = sf_wifi_channel_to_mhz(m->channel);
    if (!rx->scan_open || mhz == 0 || m->rssi >= 0 || rx->scan.n_ap >= SF_WIFI_MAX_AP) {
        rx->counters.decode_errors++;
        return SF_ERANGE;
    }
    if (!rx->scan_timed) {
        return 0;
    }
    const int32_t i = rx->scan.n_ap++;
    rx->scan.bssid[i] = (int64_t)m->bssid;
    rx->scan.rssi_dbm[i] = (float)m->rssi;
    rx->scan.freq_mhz[i] = mhz;
    return 0;
}

int sf_board_scan_end(sf_board_rx_t *const rx, const struct board_wifi_scan_end_t *const m,
                      sf_rx_event_t *const ev)
{
    if (!rx->scan_open && rx->last_scan_valid && m->scan_id == rx->last_scan_raw_id) {
        if (!rx->scan_repeat) {
            rx->counters.duplicates++; /* the SCAN_END again */
        }
        rx->scan_repeat = false;
        return SF_EDUPLICATE;
    }
    if (!rx->scan_open || m->scan_id != rx->scan_raw_id) {
        const bool was_open = rx->scan_open;
        rx->counters.decode_errors++;
        if (was_open) {
            return close_scan(rx, false, ev); /* 0 (no event) when the open scan had no board time */
        }
        return SF_ERANGE;
    }
    return close_scan(rx, rx->scan.n_ap == (int32_t)m->n_ap, ev);
}
