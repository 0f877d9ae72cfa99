/* sf_can_input.h — where frames come from: a candump -L file, standard input ("-"), or a
 * SocketCAN interface ("socketcan:IFACE").
 *
 * SocketCAN is compiled on every Linux build; where the kernel lacks AF_CAN, opening it fails with
 * SF_EUNSUPPORTED and a message, nothing else changes. File and stdin inputs report the line number
 * of each bad line so that messages can name it. */
#ifndef SF_CAN_INPUT_H
#define SF_CAN_INPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "sf_can_frame.h"

#define SF_CAN_INPUT_SOCKETCAN_PREFIX "socketcan:"

/* A file or stdin is read this much at a time (one read(2), or fread on a stream without a
 * descriptor), and split into lines in place. */
#define SF_CAN_INPUT_CHUNK_BYTES (64u * 1024u)

typedef enum { sf_can_input_file, sf_can_input_socketcan } sf_can_input_kind_t;

typedef struct {
    sf_can_input_kind_t kind;
    char name[256]; /* the spec as given, for messages */
    FILE *file;     /* file kind */
    int fd;         /* socketcan kind */
    long line_no;   /* file kind: number of the line last read (1-based) */
    const char *line; /* file kind: the line last read, newline stripped, for messages; in the read
                       * buffer (or overlong), valid until the next call */
    char overlong[512]; /* file kind: the start of a line too long to be a candump line */
    char *chunk;    /* file kind: SF_CAN_INPUT_CHUNK_BYTES read ahead (malloc'd at the first read) */
    size_t chunk_len, chunk_pos; /* bytes in chunk, and consumed */
    bool eof;       /* the end was read */
    bool skipping;  /* inside the rest of an overlong line */
} sf_can_input_t;

/* Opens a spec: "-" (stdin), "socketcan:IFACE", or a file path. SF_OK, SF_ENOENT (no such file or
 * interface), SF_EIO (unreadable), SF_EUNSUPPORTED (no AF_CAN here), SF_EINVAL. *err_text (may be
 * NULL) receives a one-line explanation on failure. */
int sf_can_input_open(sf_can_input_t *in, const char *spec, char *err_text, size_t err_size);

/* Reads the next frame: 1 a frame, 0 end of input, SF_ESYNTAX a line that is not candump -L (the
 * line is skipped; in->line_no and in->line name it), SF_ENOTCLASSIC a well-formed CAN FD line
 * (skipped: *frame has its time, id and extended flag, dlc 0; sf_candump.h), SF_EIO a read error,
 * SF_EINTR a blocking read interrupted by a signal (call again to go on). */
int sf_can_input_next(sf_can_input_t *in, sf_can_frame_t *frame);

/* Closes the file or socket that sf_can_input_open opened (never stdin, never a descriptor of a
 * zeroed input that was not opened); safe to call twice. */
void sf_can_input_close(sf_can_input_t *in);

#endif
