/* sf_board_ble.h — BLE scan windows, part of sf_board_rx (internal to it): BLE_ADV advertisements
 * grouped into one sf_rx_ble_t per window of ble.window_ms board time; the rules are in sf_board_rx.h.
 * Return codes as sf_board_rx_frame's. Cost: O(SF_BLE_MAX_BEACONS) per advertisement. */
#ifndef SF_BOARD_BLE_H
#define SF_BOARD_BLE_H

#include "board.h"
#include "sf_board_rx.h"

/* One advertisement: 1 when it closed the open window (in *ev; it then opened the next), 0 when it
 * was added, < 0 when skipped and counted. */
int sf_board_ble_adv(sf_board_rx_t *rx, const struct board_ble_adv_t *m, sf_rx_event_t *ev);

/* The board's time has reached now_us (a believed BOARD_TIME): 1 with the open window in *ev when
 * now_us is past it, else 0. */
int sf_board_ble_tick(sf_board_rx_t *rx, int64_t now_us, sf_rx_event_t *ev);

/* 1 with the open window in *ev (closed), else 0. */
int sf_board_ble_close(sf_board_rx_t *rx, sf_rx_event_t *ev);

#endif
