/* fuzz_lcm_input.c — the raw-sensor LCM replay (sf_lcm_input.c: the strict event-log reader and
 * the bounds-checked decode) on a whole log file taken from the input, read to its end as
 * `stridefixd --replay` reads it. Reference checks: only the documented codes, every bad event has a
 * message, the counters add up (events = used + other channels + bad events). */
#include <string.h>

#include "sf_error.h"
#include "sf_fuzz.h"
#include "sf_lcm_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *const data, const size_t size)
{
    FILE *const f = sf_fuzz_stream(data, size);
    if (f == NULL) {
        return 0;
    }
    sf_lcm_input_t *in = NULL;
    char err[256];
    if (sf_lcm_input_open_stream(&in, f, "fuzz.lcmlog", err, sizeof err) != SF_OK) {
        return 0;
    }
    for (;;) {
        sf_rx_event_t ev;
        int64_t t_us;
        const int rc = sf_lcm_input_next(in, &ev, &t_us);
        SF_FUZZ_CHECK(rc == 1 || rc == 0 || rc == SF_ESYNTAX || rc == SF_ECORRUPT || rc == SF_EIO);
        if (rc == 1) {
            SF_FUZZ_CHECK(ev.kind > sf_rx_none && (int)ev.kind <= SF_RX_KIND_COUNT);
            if (ev.kind == sf_rx_wifi) {
                SF_FUZZ_CHECK(ev.u.wifi.n_ap >= 0 && ev.u.wifi.n_ap <= SF_WIFI_MAX_AP);
            }
        } else if (rc == SF_ESYNTAX || rc == SF_ECORRUPT) {
            SF_FUZZ_CHECK(strlen(sf_lcm_input_error(in)) > 0);
        }
        if (rc != 1 && rc != SF_ESYNTAX) {
            break;
        }
    }
    sf_lcm_input_counters_t c;
    sf_lcm_input_counters(in, &c);
    SF_FUZZ_CHECK(c.events == c.used + c.other_channels + c.decode_errors);
    SF_FUZZ_CHECK(c.truncated + c.refused <= 1);
    sf_lcm_input_close(in);
    return 0;
}
