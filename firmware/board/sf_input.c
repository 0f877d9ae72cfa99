/* sf_input.c — CAN (candump, stdin, SocketCAN) and raw-sensor LCM replay as one input (see sf_input.h). */
#define _POSIX_C_SOURCE 200809L /* fileno */
#include "sf_input.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_can_input.h"
#include "sf_error.h"
#include "sf_file_kind.h"
#include "sf_lcm_input.h"

struct sf_input {
    sf_can_input_t can;     /* CAN inputs */
    sf_lcm_input_t *lcm;    /* LCM replay; NULL for CAN inputs */
    sf_board_rx_t rx;       /* the decoder (CAN) and the counters (both) */
    sf_can_frame_t frame;   /* the latest frame, for messages */
    uint64_t bad_syntax;
    uint64_t can_fd;        /* CAN FD lines: counted as frames of an unknown id too */
    bool flushed;           /* the end of a CAN input handed back the decoder's open BLE window */
    char name[256];
};

_Static_assert(sizeof(struct sf_input) <= 7 * 1024, "sf_input.h promises at most 7 KiB per input");

int sf_input_open(sf_input_t **const result, const char *const spec, char *const err, const size_t err_size)
{
    *result = NULL;
    sf_input_t *const in = calloc(1, sizeof *in);
    if (in == NULL) {
        snprintf(err, err_size, "out of memory");
        return SF_EIO;
    }
    sf_board_rx_init(&in->rx);
    const size_t n_prefix = strlen(SF_INPUT_LCMLOG_PREFIX);
    int rc;
    if (spec != NULL && strncmp(spec, SF_INPUT_LCMLOG_PREFIX, n_prefix) == 0) {
        rc = sf_lcm_input_open(&in->lcm, spec + n_prefix, err, err_size);
        snprintf(in->name, sizeof in->name, "%s", spec + n_prefix);
    } else {
        rc = sf_can_input_open(&in->can, spec, err, err_size);
        snprintf(in->name, sizeof in->name, "%s", in->can.name);
    }
    if (rc != SF_OK) {
        free(in);
        return rc;
    }
    *result = in;
    return SF_OK;
}

void sf_input_configure(sf_input_t *const in, const sf_params_t *const p)
{
    sf_board_rx_configure(&in->rx, p);
}

/* A replayed event: counted as the CAN decoder counts a frame, so HEALTH reads the same. */
static int next_lcm(sf_input_t *const in, sf_input_item_t *const item)
{
    sf_rx_counters_t *const c = &in->rx.counters;
    const int rc = sf_lcm_input_next(in->lcm, &item->event, &item->log_t_us);
    if (rc == 0 || rc == SF_EIO) {
        return rc;
    }
    c->frames++;
    if (rc < 0) {
        c->decode_errors++;
        return rc; /* SF_ESYNTAX, or SF_ECORRUPT: the rest of the log refused */
    }
    c->frames_ok++;
    sf_rx_count_sample(c, item->event.kind);
    item->status = SF_OK;
    return 1;
}

int sf_input_next(sf_input_t *const in, sf_input_item_t *const item)
{
    if (in->lcm != NULL) {
        return next_lcm(in, item);
    }
    const int rc = sf_can_input_next(&in->can, &in->frame);
    if (rc == SF_ESYNTAX) {
        in->bad_syntax++;
        return rc;
    }
    if (rc == SF_ENOTCLASSIC) {
        /* a frame on the bus, but not one of the board's (classic CAN only): counted as the decoder
         * counts a frame of an unknown id, not handed to it (its header would match a board id) */
        in->rx.counters.frames++;
        in->rx.counters.unknown_id++;
        in->can_fd++;
        item->log_t_us = in->frame.host_t_us;
        item->status = SF_ENOTCLASSIC;
        item->event.kind = sf_rx_none;
        return 1;
    }
    if (rc == 0 && !in->flushed) {
        in->flushed = true; /* the end: what the decoder still holds, as one more item */
        item->log_t_us = in->frame.host_t_us;
        item->status = SF_OK;
        return sf_board_rx_flush(&in->rx, &item->event) == 1 ? 1 : 0;
    }
    if (rc <= 0) {
        return rc;
    }
    item->log_t_us = in->frame.host_t_us;
    const int r = sf_board_rx_frame(&in->rx, &in->frame, &item->event);
    item->status = r < 0 ? r : SF_OK;
    if (r <= 0) {
        item->event.kind = sf_rx_none;
    }
    return 1;
}

/* What was wrong with the latest input, or NULL for a skip that is only counted. */
static const char *what(const sf_input_t *const in, const int code, char *const buf, const size_t size)
{
    const sf_can_frame_t *const f = &in->frame;
    switch (code) {
    case SF_ESYNTAX:
        return "not a candump -L line; skipped";
    case SF_ENOTCLASSIC:
        snprintf(buf, size, "CAN id 0x%" PRIX32 "%s is a CAN FD frame; the board sends classic CAN only; skipped",
                 f->id, f->extended ? " (extended)" : "");
        return buf;
    case SF_EUNKNOWN_ID:
        snprintf(buf, size, "CAN id 0x%" PRIX32 "%s is not in board.dbc; skipped", f->id,
                 f->extended ? " (extended)" : f->remote ? " (remote)" : "");
        return buf;
    case SF_ELENGTH:
        snprintf(buf, size, "CAN id 0x%03" PRIX32 " has %u data bytes, board.dbc says %u; skipped", f->id,
                 (unsigned)f->dlc, sf_board_rx_dbc_length(f->id));
        return buf;
    case SF_ERANGE:
        snprintf(buf, size, "CAN id 0x%03" PRIX32 ": signal out of range or out of sequence; skipped", f->id);
        return buf;
    case SF_EFULL:
        snprintf(buf, size, "CAN id 0x%03" PRIX32 ": BLE window already holds %d beacons; skipped", f->id,
                 SF_BLE_MAX_BEACONS);
        return buf;
    case SF_ELATE:
    case SF_ESEQ:
    case SF_EIMPLAUSIBLE:
        snprintf(buf, size, "CAN id 0x%03" PRIX32 ": %s; skipped", f->id, sf_strerror(code));
        return buf;
    default: return NULL; /* unsynced / duplicate samples: counted only, they are expected at start-up */
    }
}

bool sf_input_describe(const sf_input_t *const in, const int code, char *const buf, const size_t size)
{
    if (in->lcm != NULL && (code == SF_ESYNTAX || code == SF_ECORRUPT)) {
        snprintf(buf, size, "%s", sf_lcm_input_error(in->lcm)); /* names the log, the event and the field */
        return true;
    }
    char tmp[160];
    const char *const w = what(in, code, tmp, sizeof tmp);
    if (w == NULL) {
        return false;
    }
    if (in->lcm == NULL && in->can.kind == sf_can_input_file) {
        snprintf(buf, size, "%s:%ld: %s: '%.80s'", in->name, in->can.line_no, w, in->can.line);
    } else {
        snprintf(buf, size, "%s: %s", in->name, w);
    }
    return true;
}

void sf_input_counters(const sf_input_t *const in, sf_input_counters_t *const counters)
{
    counters->rx = in->rx.counters;
    counters->bad_syntax = in->bad_syntax;
    counters->can_fd = in->can_fd;
    counters->frames_total = in->rx.counters.frames + in->bad_syntax;
    sf_lcm_input_counters_t lc = {0};
    if (in->lcm != NULL) {
        sf_lcm_input_counters(in->lcm, &lc);
    }
    counters->replay_oversized = lc.oversized;
    counters->replay_truncated = lc.truncated;
    counters->replay_refused = lc.refused;
}

bool sf_input_nothing_valid(const sf_input_t *const in, char *const buf, const size_t size)
{
    const sf_rx_counters_t *const c = &in->rx.counters;
    if (c->frames_ok > 0) {
        return false;
    }
    if (in->lcm != NULL) {
        if (c->frames == 0) {
            snprintf(buf, size, "%s: nothing valid in the input: no sensor event (IMU MAG BARO WIFI GNSS BLE LANDMARK)", in->name);
        } else {
            snprintf(buf, size, "%s: nothing valid in the input: %" PRIu64 " sensor events, none decodes",
                     in->name, c->frames);
        }
    } else {
        snprintf(buf, size,
                 "%s: nothing valid in the input: %" PRIu64 " lines or frames read (%" PRIu64
                 " not candump -L), not one a valid board.dbc frame",
                 in->name, c->frames + in->bad_syntax, in->bad_syntax);
    }
    return true;
}

const char *sf_input_name(const sf_input_t *const in)
{
    return in->name;
}

bool sf_input_is_live(const sf_input_t *const in)
{
    return in->lcm == NULL && in->can.kind == sf_can_input_socketcan;
}

bool sf_input_is_regular_file(const sf_input_t *const in)
{
    if (in->lcm != NULL) {
        return sf_lcm_input_is_regular(in->lcm);
    }
    return in->can.kind == sf_can_input_file && in->can.file != NULL && sf_file_is_regular(fileno(in->can.file));
}

bool sf_input_spec_is_live(const char *const spec)
{
    const char *const prefix = SF_CAN_INPUT_SOCKETCAN_PREFIX;
    return spec != NULL && strncmp(spec, prefix, strlen(prefix)) == 0;
}

void sf_input_close(sf_input_t *const in)
{
    if (in == NULL) {
        return;
    }
    if (in->lcm != NULL) {
        sf_lcm_input_close(in->lcm);
    } else {
        sf_can_input_close(&in->can);
    }
    free(in);
}
