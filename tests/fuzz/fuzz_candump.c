/* fuzz_candump.c — the candump -L input (sf_can_input.c line reading, sf_candump.c parser) on any
 * bytes: the input is a candump file read line by line, as `stridefixd --input FILE` reads it.
 * Reference check: every line that parses formats back (sf_candump_format) to a line that parses to
 * the same frame; a CAN FD line (SF_ENOTCLASSIC) carries its header only (no data, not remote). */
#include <string.h>

#include "sf_can_input.h"
#include "sf_candump.h"
#include "sf_error.h"
#include "sf_fuzz.h"

static int same_frame(const sf_can_frame_t *const a, const sf_can_frame_t *const b)
{
    return a->host_t_us == b->host_t_us && a->id == b->id && a->extended == b->extended &&
           a->remote == b->remote && a->dlc == b->dlc && memcmp(a->data, b->data, a->dlc) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *const data, const size_t size)
{
    FILE *const f = sf_fuzz_stream(data, size);
    if (f == NULL) {
        return 0;
    }
    sf_can_input_t in = {.kind = sf_can_input_file, .file = f, .fd = -1};
    snprintf(in.name, sizeof in.name, "fuzz");
    for (;;) {
        sf_can_frame_t frame;
        const int rc = sf_can_input_next(&in, &frame);
        if (rc == 0 || rc == SF_EIO) {
            break;
        }
        SF_FUZZ_CHECK(rc == 1 || rc == SF_ESYNTAX || rc == SF_ENOTCLASSIC);
        if (rc == SF_ENOTCLASSIC) {
            SF_FUZZ_CHECK(frame.dlc == 0 && !frame.remote && frame.id <= (frame.extended ? 0x1FFFFFFFu : 0x7FFu));
        }
        if (rc == 1) {
            SF_FUZZ_CHECK(frame.dlc <= 8);
            char line[96];
            const int n = sf_candump_format(&frame, "can0", line, sizeof line);
            SF_FUZZ_CHECK(n > 0);
            sf_can_frame_t again;
            SF_FUZZ_CHECK(sf_candump_parse(line, &again) == SF_OK);
            SF_FUZZ_CHECK(same_frame(&frame, &again));
        }
    }
    sf_can_input_close(&in);
    return 0;
}
