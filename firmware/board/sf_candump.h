/* sf_candump.h — the can-utils `candump -L` text format, one frame per line:
 *
 *     (1700000000.123456) can0 100#0011223344556677
 *     (1700000000.123456) can0 12345678#00         (extended id: 8 hex digits)
 *     (1700000000.123456) can0 100#R                (remote frame)
 *
 * Parsing is strict: anything else (CAN FD `##`, odd hex digits, more than 8 bytes, junk after the
 * data) is SF_ESYNTAX so the caller can count and skip the line. */
#ifndef SF_CANDUMP_H
#define SF_CANDUMP_H

#include <stddef.h>

#include "sf_can_frame.h"

/* Parses one line (a trailing newline is allowed). SF_OK, SF_ESYNTAX or SF_EINVAL (NULL). Cost: one
 * pass with a table lookup per character: ~430 instructions for a replay line (10-digit seconds, 8 data
 * bytes), 627 before the table. */
int sf_candump_parse(const char *line, sf_can_frame_t *frame);

/* As sf_candump_parse on the len characters of line that its NUL follows; a NUL inside them is
 * SF_ESYNTAX (the line reader's check, without another pass over the line). Cost: a line of a board
 * replay's shape (10-digit seconds, 3-digit id, 8 data bytes) is read 8 characters a step, ~260
 * instructions (callgrind); any other line as sf_candump_parse. */
int sf_candump_parse_line(const char *line, size_t len, sf_can_frame_t *frame);

/* Formats one frame as a candump -L line with a newline; returns the length, or SF_EINVAL when
 * the buffer is too small (80 bytes always suffice). */
int sf_candump_format(const sf_can_frame_t *frame, const char *iface, char *buf, size_t size);

#endif
