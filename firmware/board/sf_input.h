/* sf_input.h — every input of stridefixd behind one interface: a candump -L file, standard input
 * ("-"), a SocketCAN interface ("socketcan:IFACE") or a raw-sensor LCM log ("lcmlog:FILE").
 *
 * CAN inputs are decoded and timed by sf_board_rx; an LCM log carries samples already decoded
 * (sf_lcm_input). Both give the same item: a log timestamp and, when the item carries a sample, one
 * sf_rx_event_t, so the daemon feeds the estimator from one switch whatever the source. Bad input is
 * not an error: it is counted in one set of counters (sf_input_counters_t, never decreasing, what
 * HEALTH reports) and skipped; sf_input_describe words it, naming the file and line.
 *
 * Errors: sf_input_open SF_OK, SF_ENOENT (no such file or interface), SF_EIO (unreadable, or a
 * directory or device: sf_file_kind.h; a FIFO is read like stdin),
 * SF_EUNSUPPORTED (no AF_CAN here), SF_EINVAL (no spec), with a message in err_text.
 * sf_input_next: see below. Memory: one heap block per open input (6704 B on x86-64, asserted
 * ≤ 7 KiB: the decoder with its Wi-Fi scan and BLE window in progress, the candump line buffer), allocated by
 * sf_input_open, and for a candump file or stdin the reader's 64 KiB chunk (SF_CAN_INPUT_CHUNK_BYTES,
 * at the first read), freed by sf_input_close; sf_input_item_t is ≈ 4 KiB (the caller's). */
#ifndef SF_INPUT_H
#define SF_INPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sf_board_rx.h"
#include "sf_rx_event.h"

#define SF_INPUT_LCMLOG_PREFIX "lcmlog:"

typedef struct sf_input sf_input_t;

/* The one set of input counters. `rx` are the decoder's (the LCM replay keeps the same ones: frames =
 * events of sensor channels, decode_errors = payloads that did not decode, imu .. landmark = samples). */
typedef struct {
    uint64_t frames_total; /* frames, lines or sensor events read, good or bad: rx.frames + bad_syntax */
    uint64_t bad_syntax;   /* candump lines that do not parse, SocketCAN reads that are not a frame */
    uint64_t can_fd;       /* well-formed CAN FD lines (not the board's: also in rx.unknown_id), skipped */
    uint64_t replay_oversized; /* LCM replay: events above the size cap, skipped (sf_lcm_input.h) */
    uint64_t replay_truncated; /* LCM replay: a last event cut short (0 or 1) */
    uint64_t replay_refused;   /* LCM replay: an untrusted header, the rest of the log refused (0 or 1) */
    sf_rx_counters_t rx;
} sf_input_counters_t;

/* One unit of input: a CAN frame (which may complete a sample, or only update the decoder, or be
 * skipped: status SF_EUNKNOWN_ID .., or SF_ENOTCLASSIC for a CAN FD line), or one replayed sensor
 * event. */
typedef struct {
    int64_t log_t_us;    /* timestamp for the log: the frame's host receive time, or the event's log time */
    int status;          /* SF_OK, or the negative code of a frame the decoder skipped (counted) */
    sf_rx_event_t event; /* kind sf_rx_none when the item carries no sample */
} sf_input_item_t;

int sf_input_open(sf_input_t **in, const char *spec, char *err_text, size_t err_size);

/* The decoder's parameters (ble.window_ms, landmark.accuracy_m; sf_board_rx_configure), before the
 * first sf_input_next; without this call, the params table's defaults. */
void sf_input_configure(sf_input_t *in, const sf_params_t *p);

/* Next item: 1 *item filled; 0 end of input (a CAN input first hands back, as one last item, the BLE
 * window still open, sf_board_rx_flush); SF_EIO a read error (errno tells); SF_ESYNTAX a line or
 * event that does not parse (counted and skipped, no item: call again); SF_EINTR a blocking read
 * (stdin, SocketCAN) interrupted by a signal (no item: call again, or stop); SF_ECORRUPT an LCM log
 * whose framing cannot be trusted from here on (counted; the rest is refused: the caller should fail). */
int sf_input_next(sf_input_t *in, sf_input_item_t *item);

/* The words for a skipped input (an SF_ESYNTAX of sf_input_next, or an item's status) of the latest
 * item, naming the input and, for files, the line: true with the text in buf, or false for skips
 * that are expected and only counted (samples before the first BOARD_TIME, repeated samples). */
bool sf_input_describe(const sf_input_t *in, int code, char *buf, size_t size);

void sf_input_counters(const sf_input_t *in, sf_input_counters_t *counters);

/* After the input ended: true, with the words in buf ("NAME: nothing valid in the input: ..."), when
 * not one frame (CAN) or sensor event (LCM replay) was valid: a PNG given as a candump, an empty file,
 * a log without sensor channels. The daemon then exits SF_EXIT_NOTHING_VALID. */
bool sf_input_nothing_valid(const sf_input_t *in, char *buf, size_t size);

/* The spec as given ("<stdin>" for "-"), for messages. */
const char *sf_input_name(const sf_input_t *in);

/* True for a live source (SocketCAN), where the logger must never wait on the disk; false for files,
 * stdin and logs, whose replay may wait rather than drop. */
bool sf_input_is_live(const sf_input_t *in);

/* True for an input read from a regular file (a candump file, an LCM log), whose reads never wait:
 * the log may be written by the reading thread (sf_lcm_out.h caller_writes). False for SocketCAN,
 * stdin, a pipe or a FIFO. */
bool sf_input_is_regular_file(const sf_input_t *in);

/* True for a spec that names a live source (socketcan:IFACE), before anything is opened. */
bool sf_input_spec_is_live(const char *spec);

/* Closes what sf_input_open opened, and only that (never a descriptor it did not open, such as
 * standard input for an LCM replay); in may be NULL. */
void sf_input_close(sf_input_t *in);

#endif
