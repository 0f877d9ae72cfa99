/* sf_board_scan.h — Wi-Fi scan reassembly, a leaf of sf_board_rx: WIFI_SCAN_BEGIN, one WIFI_AP per
 * access point and WIFI_SCAN_END become one sf_rx_wifi_t. A scan whose SCAN_END was lost is handed
 * back, marked incomplete, by the next SCAN_BEGIN; a scan the bus repeated (the same scan id and start
 * time as the scan open or just closed), a repeated AP (a scan lists each BSSID once) and a repeated
 * SCAN_END are dropped as duplicates; a start time far from the clock is refused
 * (sf_board_clock_carried). Return codes as sf_board_rx_frame's.
 *
 * The leaf keeps its own state (sf_board_scan_t, inside sf_board_rx_t) and calls nothing of
 * sf_board_rx.c: sf_board_rx hands it the decoded frame, the board clock (read only), the frame's host
 * time and the receiver's counters, which it counts into (duplicates, decode_errors, unsynced,
 * wifi_incomplete).
 *
 * Cost: O(SF_WIFI_MAX_AP) per WIFI_AP (the repeat search), O(1) otherwise. Memory: the one scan in
 * progress, sizeof(sf_board_scan_t) = 4128 B on x86-64 (asserted ≤ 4 160 B), part of
 * sf_board_rx_t; no heap. */
#ifndef SF_BOARD_SCAN_H
#define SF_BOARD_SCAN_H

#include <stdbool.h>
#include <stdint.h>

#include "board.h"
#include "sf_board_time.h"
#include "sf_rx_event.h"

struct sf_rx_counters; /* sf_rx_counters_t of sf_board_rx.h */

typedef struct {
    bool open;            /* between SCAN_BEGIN and SCAN_END */
    bool repeat;          /* frames of a repeated scan are being dropped */
    bool timed;           /* the open scan has a board time */
    bool id_started;      /* id below has been set once */
    uint8_t raw_id;       /* scan id of the open scan, as sent */
    bool last_valid;      /* the last closed scan, to recognise a repeat */
    uint8_t last_raw_id;
    uint32_t time_ms;     /* SCAN_BEGIN time of the open scan, as sent */
    uint32_t last_time_ms;
    int64_t id;           /* unwrapped id of the open scan */
    sf_rx_wifi_t wifi;    /* the scan being filled */
} sf_board_scan_t;

_Static_assert(sizeof(sf_board_scan_t) <= 4160, "sf_board_scan.h promises at most 4 160 B");

/* SCAN_BEGIN received at host_t_us: 1 with a scan still open (SCAN_END lost) in *ev, marked
 * incomplete; else 0 or a negative code as sf_board_rx_frame's. */
int sf_board_scan_begin(sf_board_scan_t *s, struct sf_rx_counters *counters, const sf_board_clock_t *clock,
                        int64_t host_t_us, const struct board_wifi_scan_begin_t *m, sf_rx_event_t *ev);

/* One WIFI_AP of the open scan: 0 when added (or its scan has no board time), < 0 when skipped. */
int sf_board_scan_ap(sf_board_scan_t *s, struct sf_rx_counters *counters, const struct board_wifi_ap_t *m);

/* SCAN_END: 1 with the scan in *ev (complete when every AP frame arrived), else 0 or < 0. */
int sf_board_scan_end(sf_board_scan_t *s, struct sf_rx_counters *counters, const struct board_wifi_scan_end_t *m,
                      sf_rx_event_t *ev);

/* The board restarted: a scan open (with a board time) is counted incomplete and dropped, and no scan
 * of the old boot counts as the last one any more. */
void sf_board_scan_on_new_epoch(sf_board_scan_t *s, struct sf_rx_counters *counters);

/* Wi-Fi channel → centre frequency [MHz]; 0 when the channel is not a 2.4 or 5 GHz channel. */
int32_t sf_wifi_channel_to_mhz(unsigned channel);

#endif
