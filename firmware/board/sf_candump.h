/* sf_candump.h — the can-utils `candump -L` text format, one frame per line:
 *
 *     (1700000000.123456) can0 100#0011223344556677
 *     (1700000000.123456) can0 12345678#00         (extended id: 8 hex digits)
 *     (1700000000.123456) can0 100#R                (remote frame)
 *     (1700000000.123456) can0 100#0011 R           (asc2log's direction flag: R received, T sent)
 *     (1700000000.123456) can0 123##1001122         (CAN FD: "##", a flags nibble, 0..64 bytes)
 *
 * The direction flag (a blank, then R or T, after the data or the R of a remote frame) is read and
 * dropped: a frame is the same frame whichever way it went (asc2log writes one on every line).
 *
 * CAN FD lines are parsed but not carried: sf_can_frame_t is a classic frame (8 data bytes) and the
 * board sends only classic CAN, so a well-formed FD line (flags one hex digit; a whole number of
 * bytes, of a length an FD DLC gives: 0..8, 12, 16, 20, 24, 32, 48 or 64) is SF_ENOTCLASSIC, with its
 * time, id and extended flag in *frame (dlc 0, no data), and the input layer counts it as a frame
 * that is not the board's (sf_input.c: unknown id) rather than as bad syntax.
 *
 * Parsing is strict otherwise: anything else (odd hex digits, more than 8 bytes of classic or 64 of
 * FD data, an FD length no DLC gives, a flag without its blank, two flags, junk after the data) is
 * SF_ESYNTAX so the caller can count and skip the line; *frame is then untouched. */
#ifndef SF_CANDUMP_H
#define SF_CANDUMP_H

#include <stddef.h>

#include "sf_can_frame.h"

/* Parses one line (a trailing newline is allowed). SF_OK, SF_ENOTCLASSIC (a CAN FD line), SF_ESYNTAX
 * or SF_EINVAL (NULL). Cost: one pass with a table lookup per character: ~430 instructions for a
 * replay line (10-digit seconds, 8 data bytes), 627 before the table. */
int sf_candump_parse(const char *line, sf_can_frame_t *frame);

/* As sf_candump_parse on the len characters of line that its NUL follows; a NUL inside them is
 * SF_ESYNTAX (the line reader's check, without another pass over the line). Cost: a line of a board
 * replay's shape (10-digit seconds, 3-digit id, 8 data bytes) is read 8 characters a step, ~260
 * instructions (callgrind over a 60 s SIL replay, 16858 lines: 269 a line at -O2, 255 at -O3; 275
 * and 262 before the direction flag); the same line with asc2log's direction flag ~400 (a failed
 * try, then the same read before the flag); any other line as sf_candump_parse. */
int sf_candump_parse_line(const char *line, size_t len, sf_can_frame_t *frame);

/* Formats one frame as a candump -L line with a newline; returns the length, or SF_EINVAL when
 * the buffer is too small (80 bytes always suffice). */
int sf_candump_format(const sf_can_frame_t *frame, const char *iface, char *buf, size_t size);

#endif
