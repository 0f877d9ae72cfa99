/* sf_board_scan.c — Wi-Fi scan reassembly, a leaf of sf_board_rx (see sf_board_scan.h). */
#include "sf_board_scan.h"

#include "sf_board_rx.h" /* sf_rx_counters_t only: nothing of sf_board_rx.c is called */
#include "sf_error.h"

int32_t sf_wifi_channel_to_mhz(const unsigned channel)
{
    if (channel >= 1 && channel <= 13) {
        return 2407 + 5 * (int32_t)channel;
    }
    if (channel == 14) {
        return 2484;
    }
    if (channel >= 32 && channel <= 177) {
        return 5000 + 5 * (int32_t)channel;
    }
    return 0;
}

/* Closes the open scan into *ev. */
static int close_scan(sf_board_scan_t *const s, sf_rx_counters_t *const counters, const bool complete,
                      sf_rx_event_t *const ev)
{
    s->open = false;
    s->last_valid = true;
    s->last_raw_id = s->raw_id;
    s->last_time_ms = s->time_ms;
    if (!s->timed) {
        return 0; /* started before the first BOARD_TIME: already counted as unsynced */
    }
    s->wifi.complete = complete;
    if (!complete) {
        counters->wifi_incomplete++;
    }
    ev->kind = sf_rx_wifi;
    ev->u.wifi = s->wifi;
    return 1;
}

int sf_board_scan_begin(sf_board_scan_t *const s, sf_rx_counters_t *const counters,
                        const sf_board_clock_t *const clock, const int64_t host_t_us,
                        const struct board_wifi_scan_begin_t *const m, sf_rx_event_t *const ev)
{
    const bool repeats = s->open ? s->raw_id == m->scan_id && s->time_ms == m->time_ms
                                 : s->last_valid && s->last_raw_id == m->scan_id && s->last_time_ms == m->time_ms;
    if (repeats) {
        counters->duplicates++; /* a scan repeated: its frames are dropped until the next scan */
        s->repeat = !s->open;
        return SF_EDUPLICATE;
    }
    s->repeat = false;
    int result = 0;
    if (s->open) {
        result = close_scan(s, counters, false, ev); /* SCAN_END was lost */
    }
    /* the full board time the frame carries, unwrapped; a corrupt one is a decode error */
    int64_t t_ms;
    const int rc = sf_board_clock_carried(clock, m->time_ms, host_t_us, &t_ms);
    if (rc == SF_ENOTSYNC) {
        counters->unsynced++;
    } else if (rc == SF_ERANGE) {
        counters->decode_errors++;
        return result != 0 ? result : rc; /* no scan opens: its APs count as orphans */
    }
    s->open = true;
    s->raw_id = m->scan_id;
    s->time_ms = m->time_ms;
    s->timed = rc == SF_OK;
    if (!s->timed) {
        return result != 0 ? result : SF_ENOTSYNC;
    }
    s->id = s->id_started ? s->id + (uint8_t)(m->scan_id - (uint8_t)s->id) : m->scan_id;
    s->id_started = true;
    s->wifi.t_us = sf_board_clock_output_us(clock, t_ms);
    s->wifi.scan_id = s->id;
    s->wifi.n_ap = 0;
    return result;
}

int sf_board_scan_ap(sf_board_scan_t *const s, sf_rx_counters_t *const counters, const struct board_wifi_ap_t *const m)
{
    if (s->repeat) {
        return SF_EDUPLICATE; /* counted once, at its SCAN_BEGIN */
    }
    for (int32_t i = 0; s->open && i < s->wifi.n_ap; i++) {
        if (s->wifi.bssid[i] == (int64_t)m->bssid) {
            counters->duplicates++; /* a scan lists each BSSID once */
            return SF_EDUPLICATE;
        }
    }
    const int32_t mhz = sf_wifi_channel_to_mhz(m->channel);
    if (!s->open || mhz == 0 || m->rssi >= 0 || s->wifi.n_ap >= SF_WIFI_MAX_AP) {
        counters->decode_errors++;
        return SF_ERANGE;
    }
    if (!s->timed) {
        return 0;
    }
    const int32_t i = s->wifi.n_ap++;
    s->wifi.bssid[i] = (int64_t)m->bssid;
    s->wifi.rssi_dbm[i] = (float)m->rssi;
    s->wifi.freq_mhz[i] = mhz;
    return 0;
}

int sf_board_scan_end(sf_board_scan_t *const s, sf_rx_counters_t *const counters,
                      const struct board_wifi_scan_end_t *const m, sf_rx_event_t *const ev)
{
    if (!s->open && s->last_valid && m->scan_id == s->last_raw_id) {
        if (!s->repeat) {
            counters->duplicates++; /* the SCAN_END again */
        }
        s->repeat = false;
        return SF_EDUPLICATE;
    }
    if (!s->open || m->scan_id != s->raw_id) {
        const bool was_open = s->open;
        counters->decode_errors++;
        if (was_open) {
            return close_scan(s, counters, false, ev); /* 0 (no event) when the open scan had no board time */
        }
        return SF_ERANGE;
    }
    return close_scan(s, counters, s->wifi.n_ap == (int32_t)m->n_ap, ev);
}

void sf_board_scan_on_new_epoch(sf_board_scan_t *const s, sf_rx_counters_t *const counters)
{
    if (s->open && s->timed) {
        counters->wifi_incomplete++;
    }
    s->open = false;
    s->last_valid = false;
}
