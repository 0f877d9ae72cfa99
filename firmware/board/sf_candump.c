/* sf_candump.c — strict reader and writer of candump -L lines (see sf_candump.h). */
#include "sf_candump.h"

#include <stdbool.h>
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

/* Whether n data bytes is a length a CAN FD DLC gives: 0..8, 12, 16, 20, 24, 32, 48, 64. */
static bool fd_length(const unsigned n)
{
    return n <= 8u || (n <= 24u && n % 4u == 0u) || n == 32u || n == 48u || n == 64u;
}

/* One pass, left to right; every check of the format in sf_candump.h, nothing more. On SF_OK (and on
 * SF_ENOTCLASSIC, with the FD frame's header) *end is the NUL that ended the line. */
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
    int rc = SF_OK;
    if (*p == 'R') {
        f.remote = true;
        p++;
    } else if (*p == '#') { /* CAN FD: "##", a flags nibble, up to 64 bytes of a valid FD length */
        if (kind_of(*++p) >= 16u) {
            return SF_ESYNTAX;
        }
        p++;
        unsigned n = 0;
        while (n < 65u && kind_of(p[0]) < 16u && kind_of(p[1]) < 16u) { /* p[1] only after a digit */
            n++;
            p += 2;
        }
        if (kind_of(p[0]) < 16u || !fd_length(n)) {
            return SF_ESYNTAX; /* an odd digit, more than 64 bytes, or a length no FD DLC gives */
        }
        rc = SF_ENOTCLASSIC; /* the header is kept (for messages), the data is not */
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
    k = kind_of(*p);
    if (k == BLANK) { /* blanks, then perhaps asc2log's direction flag */
        while ((k = kind_of(*++p)) == BLANK) {
        }
        if (*p == 'R' || *p == 'T') {
            k = kind_of(*++p);
        }
    }
    while (k == BLANK || k == LINE_END) {
        k = kind_of(*++p);
    }
    if (k != NUL_END) {
        return SF_ESYNTAX;
    }
    *frame = f;
    *end = p;
    return rc;
}

int sf_candump_parse(const char *const line, sf_can_frame_t *const frame)
{
    if (line == NULL || frame == NULL) {
        return SF_EINVAL;
    }
    const char *end;
    return parse(line, frame, &end);
}

/* ---- the replay's own shape, eight characters a step ---------------------------------------------
 * Nearly every line of a board's candump is one shape: "(" 10 + 6 digits ") " iface " " 3 hex "#" 16
 * hex. fast_line reads such a line with word-wide (SWAR) tests and arithmetic on 8 characters at a
 * time (~90 instructions instead of ~430) and hands every other line, and any doubt, to parse(): it
 * accepts only lines parse() accepts, with the same frame (test_candump_model holds both to the
 * reference parser). The words are loaded in little-endian byte order; elsewhere parse() does all. */

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define FAST_LINE 1
/* DEVIATION: GCC/clang attributes (this block is theirs: __BYTE_ORDER__). fast_line and sixteen_hex
 * stay inline at both calls of fast_line (left to itself, gcc 12 made fast_line a call at two calls:
 * 287 instructions a replay line), and other_line out of the replay's path (inline, 275). */
#define SF_ALWAYS_INLINE __attribute__((always_inline)) inline
#define SF_NOINLINE __attribute__((noinline))
#define ONES 0x0101010101010101ULL
#define HIGH (0x80u * ONES)

static uint64_t load8(const char *const p)
{
    uint64_t w;
    memcpy(&w, p, sizeof w);
    return w;
}

/* Whether all 8 bytes of w are decimal digits. */
static bool all_digits(const uint64_t w)
{
    return (w & (0xF0u * ONES)) == 0x30u * ONES && (((w + 0x06u * ONES) & (0xF0u * ONES)) == 0x30u * ONES);
}

/* The value of 8 decimal digits, the first in the lowest byte (Lemire's eight-digit SWAR parse). */
static uint64_t eight_digits(uint64_t w)
{
    w -= 0x30u * ONES;
    w = w * 10u + (w >> 8);
    return (((w & 0x000000FF000000FFULL) * (100u + (1000000ULL << 32))) +
            (((w >> 16) & 0x000000FF000000FFULL) * (1u + (10000ULL << 32)))) >>
           32;
}

/* 16 hex digits (either case) at p as 8 bytes, the first in the lowest (*bytes); false when one is
 * not a hex digit. A byte b below 0x80 is in [lo, hi] when b + (0x80 - lo) has its high bit and
 * b + (0x7F - hi) has not; the letters are tested on b | 0x20, which folds 'A'-'F' onto 'a'-'f' and
 * nothing else onto them. */
static SF_ALWAYS_INLINE bool sixteen_hex(const char *const p, uint64_t *const bytes)
{
    uint64_t all = 0;
    for (unsigned half = 0; half < 2u; half++) {
        const uint64_t w = load8(p + 8 * half);
        const uint64_t folded = w | (0x20u * ONES);
        const uint64_t digit = (w + 0x50u * ONES) & ~(w + 0x46u * ONES);
        const uint64_t letter = (folded + 0x1Fu * ONES) & ~(folded + 0x19u * ONES);
        if ((w & HIGH) != 0 || ((digit | letter) & HIGH) != HIGH) {
            return false;
        }
        const uint64_t nibbles = (w & (0x0Fu * ONES)) + ((letter & HIGH) >> 7) * 9u;
        uint64_t v = ((nibbles << 4) | (nibbles >> 8)) & 0x00FF00FF00FF00FFULL; /* bytes 0, 2, 4, 6 */
        v = (v | (v >> 8)) & 0x0000FFFF0000FFFFULL;
        v = (v | (v >> 16)) & 0xFFFFFFFFULL;
        all |= v << (32u * half);
    }
    *bytes = all;
    return true;
}

/* SF_OK with *frame for a line of the replay's shape that parse() accepts, else SF_ESYNTAX: then
 * parse() decides. line[0..len) is the line; line[len] is not read. */
static SF_ALWAYS_INLINE int fast_line(const char *const line, const size_t len, sf_can_frame_t *const frame)
{
    enum { IFACE_AT = 20, TAIL = 21 }; /* "(sssssssssss.uuuuuu) " before the iface, " iii#" + 16 after */
    if (len < IFACE_AT + 1 + TAIL || line[0] != '(' || line[11] != '.' || line[18] != ')' ||
        kind_of(line[19]) != BLANK) {
        return SF_ESYNTAX;
    }
    const uint64_t s8 = load8(line + 1);
    const uint64_t u6 = (load8(line + 12) << 16) | 0x3030u; /* "00" and the 6 digits; ") " shifted out */
    const unsigned s9 = (unsigned)line[9] - '0', s10 = (unsigned)line[10] - '0';
    if (!all_digits(s8) || !all_digits(u6) || s9 > 9u || s10 > 9u) {
        return SF_ESYNTAX;
    }
    const char *const tail = line + len - TAIL;
    for (const char *c = line + IFACE_AT; c < tail; c++) { /* the iface: anything but a blank or NUL */
        const unsigned k = kind_of(*c);
        if (k == BLANK || k == NUL_END) {
            return SF_ESYNTAX;
        }
    }
    const unsigned i0 = kind_of(tail[1]), i1 = kind_of(tail[2]), i2 = kind_of(tail[3]);
    if (kind_of(tail[0]) != BLANK || tail[4] != '#' || i0 > 7u || i1 > 15u || i2 > 15u) {
        return SF_ESYNTAX; /* i0 > 7: not a hex digit, or an id above 0x7FF */
    }
    uint64_t data;
    if (!sixteen_hex(tail + 5, &data)) {
        return SF_ESYNTAX;
    }
    /* field by field, the data in one store: a frame built aside and copied whole stalled on reading
     * back its data's narrower stores (store forwarding: a fifth of the function's cycles, perf) */
    frame->host_t_us = (int64_t)((eight_digits(s8) * 100u + s9 * 10u + s10) * 1000000u + eight_digits(u6));
    frame->id = i0 << 8 | i1 << 4 | i2;
    frame->extended = false;
    frame->remote = false;
    frame->dlc = 8;
    memcpy(frame->data, &data, sizeof data);
    return SF_OK;
}
#else
#define SF_NOINLINE
#endif

/* Every line but one of the replay's plain shape: first that shape before asc2log's direction flag
 * (" R", " T"; ~400 instructions a line, callgrind), then parse(). Out of line, so that the replay's
 * own lines do not pay for it (269 instructions a line, 275 before the flag, both callgrind). */
static SF_NOINLINE int other_line(const char *const line, const size_t len, sf_can_frame_t *const frame)
{
#ifdef FAST_LINE
    if (len > 2 && kind_of(line[len - 2]) == BLANK && (line[len - 1] == 'R' || line[len - 1] == 'T') &&
        fast_line(line, len - 2, frame) == SF_OK) {
        return SF_OK;
    }
#endif
    sf_can_frame_t f;
    const char *end;
    const int rc = parse(line, &f, &end);
    if ((rc != SF_OK && rc != SF_ENOTCLASSIC) || end != line + len) {
        return SF_ESYNTAX; /* bad, or ended by a NUL inside the line */
    }
    *frame = f;
    return rc;
}

int sf_candump_parse_line(const char *const line, const size_t len, sf_can_frame_t *const frame)
{
    if (line == NULL || frame == NULL) {
        return SF_EINVAL;
    }
#ifdef FAST_LINE
    if (fast_line(line, len, frame) == SF_OK) {
        return SF_OK;
    }
#endif
    return other_line(line, len, frame);
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
