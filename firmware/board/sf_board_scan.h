/* sf_board_scan.h — Wi-Fi scan reassembly, part of sf_board_rx (internal to it): WIFI_SCAN_BEGIN,
 * one WIFI_AP per access point and WIFI_SCAN_END become one sf_rx_wifi_t. A scan whose SCAN_END was
 * lost is handed back, marked incomplete, by the next SCAN_BEGIN; a scan the bus repeated (the same
 * scan id and start time as the scan open or just closed), a repeated AP (a scan lists each BSSID
 * once) and a repeated SCAN_END are dropped as duplicates; a start time far from the clock is refused
 * (sf_board_clock_carried). Return codes as sf_board_rx_frame's. */
#ifndef SF_BOARD_SCAN_H
#define SF_BOARD_SCAN_H

#include "board.h"
#include "sf_board_rx.h"

int sf_board_scan_begin(sf_board_rx_t *rx, const struct board_wifi_scan_begin_t *m, sf_rx_event_t *ev);
int sf_board_scan_ap(sf_board_rx_t *rx, const struct board_wifi_ap_t *m);
int sf_board_scan_end(sf_board_rx_t *rx, const struct board_wifi_scan_end_t *m, sf_rx_event_t *ev);

/* A full board time carried by a frame, unwrapped, counted when refused (in sf_board_rx.c). */
int sf_board_rx_carried_time(sf_board_rx_t *rx, uint32_t time_ms, int64_t *t_ms);

#endif
