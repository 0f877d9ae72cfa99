/* test_candump_model.c — the table-driven candump -L parser (sf_candump_parse) against a dumb
 * reference model: the straightforward parser it replaced (one range test per character class),
 * kept here verbatim but for two additions in its own style (marked, for asc2log output): CAN FD lines
 * (SF_ENOTCLASSIC with the header) and asc2log's direction flag. Seeded mutations of valid lines —
 * every byte value at every place, digits dropped and doubled, blanks, line ends, NULs — must give
 * the same verdict and, when valid (or FD), the same frame; a rejected line leaves *frame untouched
 * in both. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "sf_candump.h"
#include "sf_error.h"
#include "sf_test_rng.h"

/* ---- the reference: sf_candump.c's parser before the table (commit 52f8314) ---- */

static int ref_hex_value(const char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

static int ref_is_space(const char c)
{
    return c == ' ' || c == '\t';
}

static int reference_parse(const char *line, sf_can_frame_t *const frame)
{
    if (line == NULL || frame == NULL) {
        return SF_EINVAL;
    }
    const char *p = line;
    /* (seconds.micros) */
    if (*p++ != '(') {
        return SF_ESYNTAX;
    }
    int64_t sec = 0;
    int ndig = 0;
    while (*p >= '0' && *p <= '9') {
        if (++ndig > 12) {
            return SF_ESYNTAX;
        }
        sec = sec * 10 + (*p++ - '0');
    }
    if (ndig == 0 || *p++ != '.') {
        return SF_ESYNTAX;
    }
    int64_t usec = 0;
    ndig = 0;
    while (*p >= '0' && *p <= '9') {
        if (++ndig > 6) {
            return SF_ESYNTAX;
        }
        usec = usec * 10 + (*p++ - '0');
    }
    if (ndig != 6 || *p++ != ')' || !ref_is_space(*p)) {
        return SF_ESYNTAX;
    }
    while (ref_is_space(*p)) {
        p++;
    }
    /* interface name */
    const char *const iface = p;
    while (*p != '\0' && !ref_is_space(*p)) {
        p++;
    }
    if (p == iface || !ref_is_space(*p)) {
        return SF_ESYNTAX;
    }
    while (ref_is_space(*p)) {
        p++;
    }
    /* id#data */
    uint32_t id = 0;
    ndig = 0;
    int h;
    while ((h = ref_hex_value(*p)) >= 0) {
        if (++ndig > 8) {
            return SF_ESYNTAX;
        }
        id = (id << 4) | (uint32_t)h;
        p++;
    }
    if ((ndig != 3 && ndig != 8) || *p++ != '#') {
        return SF_ESYNTAX;
    }
    sf_can_frame_t f = {0};
    f.host_t_us = sec * 1000000 + usec;
    f.id = id;
    f.extended = (ndig == 8);
    if ((!f.extended && id > 0x7FFu) || (f.extended && id > 0x1FFFFFFFu)) {
        return SF_ESYNTAX;
    }
    int fd = 0;
    if (*p == 'R') {
        f.remote = true;
        p++;
    } else if (*p == '#') { /* added: CAN FD, "##", a flags digit, a valid FD length of bytes */
        p++;
        if (ref_hex_value(*p) < 0) {
            return SF_ESYNTAX;
        }
        p++;
        int n = 0;
        while (ref_hex_value(p[0]) >= 0) {
            if (ref_hex_value(p[1]) < 0 || n >= 64) {
                return SF_ESYNTAX;
            }
            n++;
            p += 2;
        }
        if (!(n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64)) {
            return SF_ESYNTAX;
        }
        fd = 1;
    } else {
        int n = 0;
        int hi;
        while ((hi = ref_hex_value(p[0])) >= 0) {
            const int lo = ref_hex_value(p[1]);
            if (lo < 0 || n >= 8) {
                return SF_ESYNTAX;
            }
            f.data[n++] = (uint8_t)((hi << 4) | lo);
            p += 2;
        }
        f.dlc = (uint8_t)n;
    }
    if (ref_is_space(*p)) { /* added: blanks, then perhaps a direction flag */
        while (ref_is_space(*p)) {
            p++;
        }
        if (*p == 'R' || *p == 'T') {
            p++;
        }
    }
    while (ref_is_space(*p) || *p == '\r' || *p == '\n') {
        p++;
    }
    if (*p != '\0') {
        return SF_ESYNTAX;
    }
    *frame = f;
    return fd ? SF_ENOTCLASSIC : SF_OK;
}


/* ---- the comparison ---- */

#define N_LINES 300000

static unsigned pick(rng_t *const r, const unsigned n)
{
    return (unsigned)(rng_uniform01(r) * n);
}

/* The valid CAN FD data lengths [bytes]. */
static const unsigned fd_lengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

/* A CAN FD line ("##", flags, data of a valid FD length) with a newline into buf; its length. */
static size_t fd_line(rng_t *const r, char *const buf, const size_t size)
{
    const bool extended = pick(r, 3) == 0;
    const unsigned id = extended ? pick(r, 0x20000000u) : pick(r, 0x800u);
    const unsigned n = fd_lengths[pick(r, sizeof fd_lengths / sizeof fd_lengths[0])];
    int k = snprintf(buf, size, extended ? "(%llu.%06u) can0 %08X##%X" : "(%llu.%06u) can0 %03X##%X",
                     (unsigned long long)pick(r, 2000000000u), pick(r, 1000000u), id, pick(r, 16));
    for (unsigned i = 0; i < n; i++) {
        k += snprintf(buf + k, size - (size_t)k, "%02x", pick(r, 256));
    }
    k += snprintf(buf + k, size - (size_t)k, "\n");
    assert_true(k > 0 && (size_t)k < size);
    return (size_t)k;
}

/* The line of len characters in buf, with its newline, gets asc2log's direction flag before the
 * newline (a blank or tab, R or T); its new length. */
static size_t add_direction(rng_t *const r, char *const buf, size_t len, const size_t size)
{
    assert_true(len > 0 && buf[len - 1] == '\n' && len + 3 < size);
    buf[len - 1] = pick(r, 4) == 0 ? '\t' : ' ';
    buf[len++] = pick(r, 2) ? 'R' : 'T';
    buf[len++] = '\n';
    buf[len] = '\0';
    return len;
}

/* A valid line of any shape the format allows (a sixth of them CAN FD, a quarter with a direction
 * flag), into buf (NUL-terminated); its length. */
static size_t valid_line(rng_t *const r, char *const buf, const size_t size)
{
    if (pick(r, 6) == 0) {
        const size_t len = fd_line(r, buf, size);
        return pick(r, 4) == 0 ? add_direction(r, buf, len, size) : len;
    }
    sf_can_frame_t f = {.host_t_us = (int64_t)(rng_uniform01(r) * 4e15), .extended = pick(r, 3) == 0,
                        .remote = pick(r, 8) == 0};
    f.id = f.extended ? (uint32_t)pick(r, 0x20000000u) : (uint32_t)pick(r, 0x800u);
    f.dlc = f.remote ? 0 : (uint8_t)pick(r, 9);
    for (unsigned i = 0; i < f.dlc; i++) {
        f.data[i] = (uint8_t)pick(r, 256);
    }
    const char *const ifaces[] = {"can0", "vcan12", "x", "can-bus_0"};
    const int n = sf_candump_format(&f, ifaces[pick(r, 4)], buf, size);
    assert_true(n > 0);
    if (pick(r, 4) == 0) { /* lower-case hex */
        for (int i = 0; i < n; i++) {
            if (buf[i] >= 'A' && buf[i] <= 'F') {
                buf[i] = (char)(buf[i] - 'A' + 'a');
            }
        }
    }
    return pick(r, 4) == 0 ? add_direction(r, buf, (size_t)n, size) : (size_t)n;
}

/* Mutates the line in buf (of len characters, NUL-terminated again after); its new length, which a
 * NUL put inside it does not shorten. */
static size_t mutate(rng_t *const r, char *const buf, size_t len, const size_t size)
{
    const char interesting[] = {' ', '\t', '\r', '\n', '\0', '#', '.', '(', ')', 'R', 'T', '0', '9', 'a', 'f',
                                'A', 'F', 'g', 'G', '/', ':', '@', '`', (char)0xFF, (char)0x80};
    const unsigned n_mut = pick(r, 4);
    for (unsigned m = 0; m < n_mut && len > 0; m++) {
        const size_t at = pick(r, (unsigned)len);
        switch (pick(r, 4)) {
        case 0: buf[at] = (char)pick(r, 256); break;                                  /* any byte */
        case 1: buf[at] = interesting[pick(r, sizeof interesting)]; break;              /* a class edge */
        case 2: memmove(buf + at, buf + at + 1, len - at); len--; break;                /* drop one */
        default:
            if (len + 2 < size) { /* double one */
                memmove(buf + at + 1, buf + at, len - at + 1);
                len++;
            }
        }
    }
    buf[len] = '\0';
    return len;
}

/* The same verdict's frame: field by field after a parse (a struct copy need not carry its padding,
 * e.g. clang's), every byte untouched after a refusal (both start as 0x5A). */
static bool same_frame(const int rc, const sf_can_frame_t *const a, const sf_can_frame_t *const b)
{
    return rc != SF_OK && rc != SF_ENOTCLASSIC ? memcmp(a, b, sizeof *a) == 0
                       : a->host_t_us == b->host_t_us && a->id == b->id && a->extended == b->extended &&
                             a->remote == b->remote && a->dlc == b->dlc && memcmp(a->data, b->data, sizeof a->data) == 0;
}

static void test_table_parser_agrees_with_the_reference(void **state)
{
    (void)state;
    rng_t rng = {0xca7d0a11ULL};
    int valid = 0, invalid = 0, fd = 0;
    for (int i = 0; i < N_LINES; i++) {
        char buf[256]; /* a 64-byte FD line and its mutations */
        const size_t len = valid_line(&rng, buf, sizeof buf);
        mutate(&rng, buf, len, sizeof buf);
        sf_can_frame_t a, b;
        memset(&a, 0x5A, sizeof a);
        memset(&b, 0x5A, sizeof b);
        const int ra = sf_candump_parse(buf, &a);
        const int rb = reference_parse(buf, &b);
        if (ra != rb || !same_frame(ra, &a, &b)) {
            fail_msg("line \"%s\": parser %d, reference %d (or different frames)", buf, ra, rb);
        }
        valid += ra == SF_OK;
        invalid += ra == SF_ESYNTAX;
        fd += ra == SF_ENOTCLASSIC;
    }
    assert_true(valid > N_LINES / 5 && invalid > N_LINES / 5); /* both verdicts well covered */
    assert_true(fd > N_LINES / 50);
}

/* A line of the shape a board's replay has (sf_candump.c's fast_line): 10-digit seconds, a standard
 * id of 3 hex digits (some above 0x7FF), 8 data bytes; either case, sometimes a tab, a quarter of
 * them with asc2log's direction flag. Its length. */
static size_t replay_line(rng_t *const r, char *const buf, const size_t size)
{
    const char *const ifaces[] = {"can0", "vcan12", "x", "can-bus_0", "a\rb"};
    const unsigned long long sec = 1000000000ull + (unsigned long long)(rng_uniform01(r) * 8.9e9);
    const unsigned usec = pick(r, 1000000u), id = pick(r, 8) == 0 ? 0x800u + pick(r, 0x800u) : pick(r, 0x800u);
    char data[17];
    for (int i = 0; i < 16; i++) {
        data[i] = "0123456789ABCDEF"[pick(r, 16)];
    }
    data[16] = '\0';
    const char *const flags[] = {"", "", "", "", "", " R", " T", "\tR"};
    const int n = snprintf(buf, size, "(%llu.%06u)%c%s%c%03X#%s%s", sec, usec, pick(r, 8) == 0 ? '\t' : ' ',
                           ifaces[pick(r, 5)], pick(r, 8) == 0 ? '\t' : ' ', id, data, flags[pick(r, 8)]);
    assert_true(n > 0 && (size_t)n < size);
    if (pick(r, 4) == 0) {
        for (int i = 0; i < n; i++) {
            if (buf[i] >= 'A' && buf[i] <= 'F') {
                buf[i] = (char)(buf[i] - 'A' + 'a');
            }
        }
    }
    return (size_t)n;
}

/* sf_candump_parse_line, the reader's entry (with its replay-shaped fast path), against the reference
 * on the line up to its NUL: the same verdict and frame, except that a NUL inside the len characters
 * is SF_ESYNTAX. Replay-shaped lines and lines of every shape, both mutated. */
static void test_line_parser_agrees_with_the_reference(void **state)
{
    (void)state;
    rng_t rng = {0x5eed1e55ULL};
    int valid = 0, invalid = 0, fd = 0;
    for (int i = 0; i < N_LINES; i++) {
        char buf[256]; /* a 64-byte FD line and its mutations */
        size_t len = i % 4 == 3 ? valid_line(&rng, buf, sizeof buf) : replay_line(&rng, buf, sizeof buf);
        if (len > 0 && buf[len - 1] == '\n') {
            buf[--len] = '\0'; /* the reader drops the newline */
        }
        len = pick(&rng, 3) == 0 ? len : mutate(&rng, buf, len, sizeof buf);
        sf_can_frame_t a, b;
        memset(&a, 0x5A, sizeof a);
        memset(&b, 0x5A, sizeof b);
        const int ra = sf_candump_parse_line(buf, len, &a);
        int rb = reference_parse(buf, &b);
        if ((rb == SF_OK || rb == SF_ENOTCLASSIC) && strlen(buf) != len) {
            rb = SF_ESYNTAX; /* a NUL inside the line */
            memset(&b, 0x5A, sizeof b);
        }
        if (ra != rb || !same_frame(ra, &a, &b)) {
            fail_msg("line \"%s\" (%zu chars): parser %d, reference %d (or different frames)", buf, len, ra, rb);
        }
        valid += ra == SF_OK;
        invalid += ra == SF_ESYNTAX;
        fd += ra == SF_ENOTCLASSIC;
    }
    assert_true(valid > N_LINES / 5 && invalid > N_LINES / 5 && fd > N_LINES / 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_parser_agrees_with_the_reference),
        cmocka_unit_test(test_line_parser_agrees_with_the_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
