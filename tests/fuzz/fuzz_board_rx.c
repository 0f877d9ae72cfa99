/* fuzz_board_rx.c — the frame decoder (sf_board_rx_frame) on a sequence of frames taken from the
 * input, 12 bytes each: id selector (below 0xF0: one of the DBC's ids, so most frames reach a
 * handler; else the next two bytes form a raw 11-bit id), flags (dlc = low nibble mod 9, bit 4
 * extended, bit 5 remote), host time step [µs, 2 bytes] and 8 data bytes. Reference checks: the
 * counters never decrease and add up (frames = ok + every skip kind), events carry a known kind and a
 * scan never more than SF_WIFI_MAX_AP access points, a BLE window 1 .. SF_BLE_MAX_BEACONS beacons. */
#include <string.h>

#include "sf_board_rx.h"
#include "sf_error.h"
#include "sf_fuzz.h"

#define RECORD_BYTES 12

static const uint32_t dbc_ids[] = {0x080, 0x100, 0x101, 0x110, 0x120, 0x200, 0x201, 0x202, 0x300, 0x301, 0x7f0, 0x210, 0x400};

static sf_board_rx_t rx; /* 5.5 KiB: static rather than on the stack; re-initialised per input */

int LLVMFuzzerTestOneInput(const uint8_t *const data, const size_t size)
{
    sf_board_rx_init(&rx);
    int64_t host_t_us = 1700000000000000LL;
    uint64_t skipped = 0;
    for (size_t at = 0; at + RECORD_BYTES <= size; at += RECORD_BYTES) {
        const uint8_t *const r = data + at;
        sf_can_frame_t f = {0};
        f.id = r[0] < 0xF0u ? dbc_ids[r[0] % (sizeof dbc_ids / sizeof dbc_ids[0])]
                            : ((uint32_t)(r[2] & 0x07u) << 8) | r[3];
        f.dlc = (uint8_t)((r[1] & 0x0Fu) % 9u);
        f.extended = (r[1] & 0x10u) != 0;
        f.remote = (r[1] & 0x20u) != 0;
        host_t_us += (int64_t)(((uint32_t)r[2] << 8) | r[3]);
        f.host_t_us = host_t_us;
        memcpy(f.data, r + 4, 8);
        const sf_rx_counters_t before = rx.counters;
        sf_rx_event_t ev;
        const int rc = sf_board_rx_frame(&rx, &f, &ev);
        const sf_rx_counters_t *const c = &rx.counters;
        SF_FUZZ_CHECK(c->frames == before.frames + 1);
        SF_FUZZ_CHECK(c->frames_ok >= before.frames_ok && c->decode_errors >= before.decode_errors);
        SF_FUZZ_CHECK(rc == 0 || rc == 1 || rc == SF_EUNKNOWN_ID || rc == SF_ELENGTH || rc == SF_ERANGE ||
                      rc == SF_ENOTSYNC || rc == SF_EDUPLICATE || rc == SF_ELATE || rc == SF_ESEQ || rc == SF_EFULL);
        skipped += rc < 0;
        if (rc == 1) {
            SF_FUZZ_CHECK(ev.kind > sf_rx_none && (int)ev.kind <= SF_RX_KIND_COUNT);
            if (ev.kind == sf_rx_wifi) {
                SF_FUZZ_CHECK(ev.u.wifi.n_ap >= 0 && ev.u.wifi.n_ap <= SF_WIFI_MAX_AP);
            }
            if (ev.kind == sf_rx_ble) {
                SF_FUZZ_CHECK(ev.u.ble.n >= 1 && ev.u.ble.n <= SF_BLE_MAX_BEACONS);
            }
        }
    }
    SF_FUZZ_CHECK(rx.counters.frames == size / RECORD_BYTES);
    SF_FUZZ_CHECK(rx.counters.frames_ok + skipped <= rx.counters.frames);
    return 0;
}
