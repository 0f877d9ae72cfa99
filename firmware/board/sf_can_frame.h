/* sf_can_frame.h — one classic CAN frame as received, with the host's receive time. */
#ifndef SF_CAN_FRAME_H
#define SF_CAN_FRAME_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    int64_t host_t_us; /* receive time on the logger's clock [µs since the Unix epoch] */
    uint32_t id;       /* 11-bit (or 29-bit when extended) identifier */
    bool extended;
    bool remote;
    uint8_t dlc; /* bytes of data, 0..8 */
    uint8_t data[8];
} sf_can_frame_t;

#endif
