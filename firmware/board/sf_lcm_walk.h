/* sf_lcm_walk.h — bounds walk over an LCM encoding before the generated decoder runs on it.
 *
 * DEVIATION: the LCM C decoder (lcm_coretypes.h, 1.3 and 1.5) computes `int total = sizeof(T) *
 * count` (overflow for count ≥ 2^28 lets it read past the buffer), allocates `sizeof(T) * count` for a
 * negative count (a huge request) and does not check that strings end with NUL. So every reader of
 * hostile bytes (the site file, sf_site.c; the raw-sensor replay, sf_rx_lcm.c) first walks the type's
 * layout by hand — fixed fields skipped, each count checked against the bytes left for the arrays it
 * sizes, strings checked — and calls the generated decode only when the walk passed. A walk must
 * follow its .lcm file field by field; the type hash check and the round-trip tests catch a layout
 * change that is not mirrored.
 *
 * Messages go to err as "<name>: <what>" (the walk's name, e.g. the file); every failure is
 * SF_ESYNTAX. Cost: O(fields), no allocation. */
#ifndef SF_LCM_WALK_H
#define SF_LCM_WALK_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    const uint8_t *p; /* the encoding */
    size_t size;      /* its bytes */
    size_t pos;       /* bytes walked so far */
    const char *name; /* message prefix */
    char *err;        /* message buffer (may be NULL) */
    size_t err_size;
} sf_lcm_walk_t;

/* "<name>: <formatted text>" into err (when err_size > 0); returns rc. */
int sf_lcm_failf(char *err, size_t err_size, const char *name, int rc, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* The big-endian int32 at p (LCM's byte order). */
int32_t sf_lcm_be32(const uint8_t *p);

/* Skips a fixed-size field (or several): SF_OK, or SF_ESYNTAX when fewer than bytes are left. */
int sf_lcm_walk_skip(sf_lcm_walk_t *w, size_t bytes, const char *field);

/* An LCM string: int32 length (≥ 1, including the NUL), then that many bytes ending with NUL. */
int sf_lcm_walk_string(sf_lcm_walk_t *w, const char *field);

/* A count, then the arrays it sizes (element_bytes = bytes per index over all those arrays): the
 * count must be ≥ 0 and its arrays must fit in what is left. */
int sf_lcm_walk_count(sf_lcm_walk_t *w, const char *field, size_t element_bytes);

/* SF_OK when the walk used every byte; SF_ESYNTAX naming the trailing bytes after type. */
int sf_lcm_walk_end(const sf_lcm_walk_t *w, const char *type);

#endif
