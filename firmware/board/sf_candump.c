/* sf_candump.c — strict reader and writer of candump -L lines (see sf_candump.h). */
#include "sf_candump.h"

#include <stdio.h>
#include <string.h>

#include "sf_error.h"

/* One table lookup per character instead of a chain of range tests: the hex value (0..15) of a hex
 * digit, else one of the classes below. The replay reads a million lines an hour of walking, and
 * the parser was a sixth of the daemon's instructions (627 per line). */
enum { NOT_HEX = 16, BLANK = 17, LINE_END = 18, NUL_END = 19 };

#define HEX_ROW(c) (uint8_t)((c) >= '0' && (c) <= '9' ? (c) - '0' : (c) >= 'a' && (c) <= 'f' ? (c) - 'a' + 10 \
                    : (c) >= 'A' && (c) <= 'F' ? (c) - 'A' + 10 : (c) == ' ' || (c) == '\t' ? BLANK \
                    : (c) == '\r' || (c) == '\n' ? LINE_END : (c) == '\0' ? NUL_END : NOT_HEX)
#define ROW4(c) HEX_ROW(c), HEX_ROW((c) + 1), HEX_ROW((c) + 2), HEX_ROW((c) + 3)
#define ROW16(c) ROW4(c), ROW4((c) + 4), ROW4((c) + 8), ROW4((c) + 12)
static const uint8_t kind[256] = {ROW16(0),   ROW16(16),  ROW16(32),  ROW16(48),  ROW16(64),  ROW16(80),
                                  ROW16(96),  ROW16(112), ROW16(128), ROW16(144), ROW16(160), ROW16(176),
                                  ROW16(192), ROW16(208), ROW16(224), ROW16(240)};

static unsigned kind_of(const char c)
{
    return kind[(unsigned char)c];
}

/* Decimal digits at *pp: their value and count (*n_digits); the caller refuses a count above what
 * it allows, so the value may wrap (unsigned) on a long run without harm. Two digits a step (the
 * second is read only after a first digit, so never past the NUL): 16 digits a line. */
static inline uint64_t decimal(const char **const pp, long *const n_digits)
{
    const unsigned char *const start = (const unsigned char *)*pp;
    const unsigned char *p = start;
    uint64_t v = 0;
    unsigned d;
    while ((d = (unsigned)p[0] - '0') <= 9u) {
        const unsigned e = (unsigned)p[1] - '0';
        if (e > 9u) {
            v = v * 10u + d;
            p++;
            break;
        }
        v = v * 100u + d * 10u + e;
        p += 2;
    }
    *pp = (const char *)p;
    *n_digits = p - start;
    return v;
}

/* One pass, left to right; every check of the format in sf_candump.h, nothing more. On success *end
 * is the NUL that ended the line. */
static int parse(const char *const line, sf_can_frame_t *const frame, const char **const end)
{
    const char *p = line;
    /* (seconds.micros) */
    if (*p++ != '(') {
        return SF_ESYNTAX;
    }
    long ndig;
    const uint64_t sec = decimal(&p, &ndig);
    if (ndig == 0 || ndig > 12 || *p++ != '.') {
        return SF_ESYNTAX;
    }
    const uint64_t usec = decimal(&p, &ndig);
    if (ndig != 6 || *p++ != ')' || kind_of(*p) != BLANK) {
        return SF_ESYNTAX;
    }
    while (kind_of(*++p) == BLANK) {
    }
    /* interface name: anything up to the next blank */
    const char *const iface = p;
    unsigned k;
    while ((k = kind_of(*p)) != BLANK && k != NUL_END) {
        p++;
    }
    if (p == iface || k != BLANK) {
        return SF_ESYNTAX;
    }
    while (kind_of(*++p) == BLANK) {
    }
    /* id#data */
    uint32_t id = 0;
    const char *const id_start = p;
    while ((k = kind_of(*p)) < 16u && p - id_start < 9) {
        id = (id << 4) | k;
        p++;
    }
    const long n_id = p - id_start;
    if ((n_id != 3 && n_id != 8) || *p++ != '#') {
        return SF_ESYNTAX;
    }
    sf_can_frame_t f = {.host_t_us = (int64_t)(sec * 1000000u + usec), .id = id, .extended = n_id == 8};
    if ((!f.extended && id > 0x7FFu) || (f.extended && id > 0x1FFFFFFFu)) {
        return SF_ESYNTAX;
    }
    if (*p == 'R') {
        f.remote = true;
        p++;
    } else {
        unsigned n = 0;
        unsigned hi, lo;
        while (n < 8u && (hi = kind_of(p[0])) < 16u && (lo = kind_of(p[1])) < 16u) { /* p[1] only after a digit */
            f.data[n++] = (uint8_t)(hi << 4 | lo);
            p += 2;
        }
        if (kind_of(p[0]) < 16u) {
            return SF_ESYNTAX; /* an odd digit, or a ninth byte */
        }
        f.dlc = (uint8_t)n;
    }
    while ((k = kind_of(*p)) == BLANK || k == LINE_END) {
        p++;
    }
    if (k != NUL_END) {
        return SF_ESYNTAX;
    }
    *frame = f;
    *end = p;
    return SF_OK;
}

int sf_candump_parse(const char *const line, sf_can_frame_t *const frame)
{
    if (line == NULL || frame == NULL) {
        return SF_EINVAL;
    }
    const char *end;
    return parse(line, frame, &end);
}

int sf_candump_parse_line(const char *const line, const size_t len, sf_can_frame_t *const frame)
{
    if (line == NULL || frame == NULL) {
        return SF_EINVAL;
    }
    sf_can_frame_t f;
    const char *end;
    if (parse(line, &f, &end) != SF_OK || end != line + len) {
        return SF_ESYNTAX; /* bad, or ended by a NUL inside the line */
    }
    *frame = f;
    return SF_OK;
}

int sf_candump_format(const sf_can_frame_t *const frame, const char *const iface, char *const buf,
                      const size_t size)
{
    char data[17] = {0};
    for (unsigned i = 0; i < frame->dlc && i < 8; i++) {
        snprintf(&data[2 * i], 3, "%02X", frame->data[i]);
    }
    const long long sec = (long long)(frame->host_t_us / 1000000);
    const long long usec = (long long)(frame->host_t_us % 1000000);
    const int n = frame->extended
                      ? snprintf(buf, size, "(%lld.%06lld) %s %08X#%s\n", sec, usec, iface, (unsigned)frame->id,
                                 frame->remote ? "R" : data)
                      : snprintf(buf, size, "(%lld.%06lld) %s %03X#%s\n", sec, usec, iface, (unsigned)frame->id,
                                 frame->remote ? "R" : data);
    if (n < 0 || (size_t)n >= size) {
        return SF_EINVAL;
    }
    return n;
}
