/* test_candump.c — the candump -L parser and formatter (sf_candump.h: asc2log's direction flags and
 * CAN FD lines too) and the frame inputs (sf_can_input.h): files, bad lines with their line numbers,
 * a NUL inside a line, lines across the reader's chunks from a file and a pipe, missing files,
 * SocketCAN where the kernel has no AF_CAN. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "sf_can_input.h"
#include "sf_candump.h"
#include "sf_error.h"

static void test_parse_standard_id_8_bytes(void **state)
{
    (void)state;
    sf_can_frame_t f;
    assert_int_equal(sf_candump_parse("(1700000000.123456) can0 100#0011223344556677", &f), SF_OK);
    assert_int_equal(f.host_t_us, 1700000000123456LL);
    assert_int_equal(f.id, 0x100);
    assert_false(f.extended);
    assert_false(f.remote);
    assert_int_equal(f.dlc, 8);
    const uint8_t want[8] = {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77};
    assert_memory_equal(f.data, want, 8);
}

static void test_parse_extended_id(void **state)
{
    (void)state;
    sf_can_frame_t f;
    assert_int_equal(sf_candump_parse("(1700000000.000001) vcan0 12345678#00\n", &f), SF_OK);
    assert_int_equal(f.host_t_us, 1700000000000001LL);
    assert_int_equal(f.id, 0x12345678);
    assert_true(f.extended);
    assert_int_equal(f.dlc, 1);
    assert_int_equal(f.data[0], 0x00);
    /* the largest 29-bit id */
    assert_int_equal(sf_candump_parse("(1.000000) can0 1FFFFFFF#", &f), SF_OK);
    assert_int_equal(f.id, 0x1FFFFFFF);
    assert_true(f.extended);
}

static void test_parse_remote(void **state)
{
    (void)state;
    sf_can_frame_t f;
    assert_int_equal(sf_candump_parse("(1700000000.123456) can0 100#R", &f), SF_OK);
    assert_true(f.remote);
    assert_int_equal(f.id, 0x100);
    assert_int_equal(f.dlc, 0);
}

static void test_parse_every_length(void **state)
{
    (void)state;
    char line[80];
    for (int n = 0; n <= 8; n++) {
        int k = snprintf(line, sizeof line, "(12.500000) can0 7F0#");
        for (int i = 0; i < n; i++) {
            k += snprintf(line + k, sizeof line - (size_t)k, "%02x", 0xA0 + i); /* lower-case hex too */
        }
        sf_can_frame_t f;
        assert_int_equal(sf_candump_parse(line, &f), SF_OK);
        assert_int_equal(f.dlc, n);
        assert_int_equal(f.id, 0x7F0);
        assert_int_equal(f.host_t_us, 12500000);
        for (int i = 0; i < n; i++) {
            assert_int_equal(f.data[i], 0xA0 + i);
        }
    }
}

static void test_parse_line_endings(void **state)
{
    (void)state;
    const char *const lines[] = {
        "(1.000000) can0 080#0102\n",
        "(1.000000) can0 080#0102\r\n",
        "(1.000000) can0 080#0102\r",
        "(1.000000)\tcan0\t080#0102",
    };
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        sf_can_frame_t f;
        assert_int_equal(sf_candump_parse(lines[i], &f), SF_OK);
        assert_int_equal(f.dlc, 2);
        assert_int_equal(f.data[1], 0x02);
    }
}

static void test_parse_garbage_is_syntax_error(void **state)
{
    (void)state;
    const char *const bad[] = {
        "",
        "\n",
        "1700000000.123456) can0 100#00",                  /* missing ( */
        "(1700000000.123456 can0 100#00",                  /* missing ) */
        "(1700000000.12345) can0 100#00",                  /* 5 fraction digits */
        "(1700000000.1234567) can0 100#00",                /* 7 fraction digits */
        "(.123456) can0 100#00",                           /* no seconds */
        "(1700000000.123456)can0 100#00",                  /* no space after ) */
        "(1700000000.123456) can0",                        /* no frame */
        "(1700000000.123456) 100#00",                      /* no interface */
        "(1700000000.123456) can0 100#001",                /* odd hex digits */
        "(1700000000.123456) can0 100#0g",                 /* not hex */
        "(1700000000.123456) can0 100#001122334455667788", /* 9 bytes */
        "(1700000000.123456) can0 100##0011",              /* CAN FD, an odd digit after the flags */
        "(1700000000.123456) can0 100##",                  /* CAN FD without flags */
        "(1700000000.123456) can0 100##g0011",             /* CAN FD, flags not hex */
        "(1700000000.123456) can0 100##1R",                /* CAN FD has no remote frames */
        "(1700000000.123456) can0 100#00 junk",            /* junk after the data */
        "(1700000000.123456) can0 100#00R",                /* a direction flag without its blank */
        "(1700000000.123456) can0 100#00 r",               /* a direction flag in lower case */
        "(1700000000.123456) can0 100#00 X",               /* no such direction */
        "(1700000000.123456) can0 100#00 RT",              /* two flags */
        "(1700000000.123456) can0 100#00 R T",             /* two flags */
        "(1700000000.123456) can0 100#00 R0",              /* junk after the flag */
        "(1700000000.123456) can0 100#00\r R",             /* a flag after a line end */
        "(1700000000.123456) can0 100#R00",                /* data after R */
        "(1700000000.123456) can0 100",                    /* no # */
        "(1700000000.123456) can0 10#00",                  /* 2-digit id */
        "(1700000000.123456) can0 1000#00",                /* 4-digit id */
        "(1700000000.123456) can0 800#00",                 /* > 0x7FF in 3 digits */
        "(1700000000.123456) can0 FFF#00",                 /* > 0x7FF in 3 digits */
        "(1700000000.123456) can0 20000000#00",            /* > 29 bits */
        "(1700000000.123456) can0 123456789#00",           /* 9-digit id */
        "(1700000000.123456) can0 #00",                    /* no id */
        "(1700000000.123456) can0 100#00\n\nx",            /* junk after the newline */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sf_can_frame_t f;
        memset(&f, 0x5A, sizeof f);
        const int rc = sf_candump_parse(bad[i], &f);
        if (rc != SF_ESYNTAX) {
            fail_msg("bad[%zu] \"%s\": got %d, want SF_ESYNTAX (%d)", i, bad[i], rc, SF_ESYNTAX);
        }
        assert_int_equal(f.id, 0x5A5A5A5A); /* *frame untouched on error */
    }
}

/* asc2log writes a direction flag after every frame ("R" received, "T" sent: can-utils' asc2log
 * output, which must replay like candump -L); each line is the frame of the line without it, whichever entry reads it (the
 * replay-shaped line takes sf_candump_parse_line's fast path). */
static void test_parse_direction_flag_is_the_same_frame(void **state)
{
    (void)state;
    const char *const pairs[][2] = {
        {"(1700000000.123456) can0 100#0011223344556677 R", "(1700000000.123456) can0 100#0011223344556677"},
        {"(1700000000.123456) can0 100#0011223344556677 T", "(1700000000.123456) can0 100#0011223344556677"},
        {"(1700000000.123456) can0 7F0#00112233445566aa\tR", "(1700000000.123456) can0 7F0#00112233445566aa"},
        {"(1700000000.123456) can0 100#0011 R", "(1700000000.123456) can0 100#0011"},
        {"(1700000000.123456) can0 100#0011  T  \r", "(1700000000.123456) can0 100#0011"},
        {"(1700000000.123456) can0 12345678#00 R", "(1700000000.123456) can0 12345678#00"},
        {"(1700000000.123456) can0 101#R R", "(1700000000.123456) can0 101#R"},
        {"(1700000000.123456) can0 124# T", "(1700000000.123456) can0 124#"},
        {"(1.000000) vcan12 080#0102 R\n", "(1.000000) vcan12 080#0102"},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        sf_can_frame_t f, g, h;
        memset(&f, 0, sizeof f);
        memset(&g, 0, sizeof g);
        memset(&h, 0, sizeof h);
        assert_int_equal(sf_candump_parse(pairs[i][0], &f), SF_OK);
        assert_int_equal(sf_candump_parse(pairs[i][1], &g), SF_OK);
        const size_t len = strcspn(pairs[i][0], "\n");
        char line[96];
        memcpy(line, pairs[i][0], len);
        line[len] = '\0';
        if (sf_candump_parse_line(line, len, &h) != SF_OK) {
            fail_msg("pair %zu: sf_candump_parse_line refused \"%s\"", i, line);
        }
        assert_memory_equal(&f, &g, sizeof f);
        assert_int_equal(h.host_t_us, g.host_t_us);
        assert_int_equal(h.id, g.id);
        assert_int_equal(h.extended, g.extended);
        assert_int_equal(h.remote, g.remote);
        assert_int_equal(h.dlc, g.dlc);
        assert_memory_equal(h.data, g.data, sizeof h.data);
    }
}

/* A CAN FD line (candump -L: "##", a flags nibble, the data) of n bytes into line; its length. */
static size_t fd_line(char *const line, const size_t size, const char *const id, const unsigned flags,
                      const unsigned n, const char *const tail)
{
    int k = snprintf(line, size, "(1700000000.654321) can0 %s##%X", id, flags);
    for (unsigned i = 0; i < n; i++) {
        k += snprintf(line + k, size - (size_t)k, "%02X", (i * 37u) & 0xFFu);
    }
    k += snprintf(line + k, size - (size_t)k, "%s", tail);
    assert_true(k > 0 && (size_t)k < size);
    return (size_t)k;
}

/* Every length 0..65 bytes: the FD lengths (0..8, 12, 16, 20, 24, 32, 48, 64) are SF_ENOTCLASSIC
 * with the frame's time and id (not a board frame: the input layer counts and skips it), the others
 * bad syntax with *frame untouched; both entries, with and without a direction flag. */
static void test_parse_can_fd_lines(void **state)
{
    (void)state;
    int n_fd = 0;
    for (unsigned n = 0; n <= 65; n++) {
        const bool valid = n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
        for (int variant = 0; variant < 4; variant++) {
            char line[200];
            const char *const id = variant % 2 ? "1ABCDEF0" : "123";
            const size_t len = fd_line(line, sizeof line, id, (unsigned)variant * 5u, n, variant >= 2 ? " R" : "");
            sf_can_frame_t f, g;
            memset(&f, 0x5A, sizeof f);
            memset(&g, 0x5A, sizeof g);
            const int rc = sf_candump_parse(line, &f);
            const int rl = sf_candump_parse_line(line, len, &g);
            if (rc != (valid ? SF_ENOTCLASSIC : SF_ESYNTAX) || rl != rc) {
                fail_msg("\"%s\" (%u bytes): got %d and %d, want %d", line, n, rc, rl,
                         valid ? SF_ENOTCLASSIC : SF_ESYNTAX);
            }
            if (!valid) {
                assert_int_equal(f.id, 0x5A5A5A5A);
                assert_int_equal(g.id, 0x5A5A5A5A);
                continue;
            }
            n_fd++;
            assert_int_equal(f.host_t_us, 1700000000654321LL);
            assert_int_equal(f.id, variant % 2 ? 0x1ABCDEF0u : 0x123u);
            assert_int_equal(f.extended, variant % 2 == 1);
            assert_false(f.remote);
            assert_int_equal(f.dlc, 0); /* the data is not carried */
            assert_int_equal(g.host_t_us, f.host_t_us);
            assert_int_equal(g.id, f.id);
            assert_int_equal(g.dlc, 0);
        }
    }
    assert_int_equal(n_fd, 16 * 4);
}

static void test_parse_null_is_einval(void **state)
{
    (void)state;
    sf_can_frame_t f;
    assert_int_equal(sf_candump_parse(NULL, &f), SF_EINVAL);
    assert_int_equal(sf_candump_parse("(1.000000) can0 100#00", NULL), SF_EINVAL);
}

static void test_format_parse_round_trip(void **state)
{
    (void)state;
    srand(12345);
    for (int i = 0; i < 2000; i++) {
        sf_can_frame_t f;
        memset(&f, 0, sizeof f);
        f.extended = (i % 3) == 0;
        f.remote = (i % 7) == 0;
        f.id = f.extended ? (uint32_t)rand() & 0x1FFFFFFFu : (uint32_t)rand() & 0x7FFu;
        f.host_t_us = (int64_t)rand() * 1000 + i;
        f.dlc = (uint8_t)(f.remote ? 0 : i % 9);
        for (size_t k = 0; k < f.dlc && k < sizeof f.data; k++) { /* the bound: gcc 12 -O3 -Wstringop-overflow */
            f.data[k] = (uint8_t)rand();
        }
        char buf[80];
        const int n = sf_candump_format(&f, "can0", buf, sizeof buf);
        assert_true(n > 0);
        assert_int_equal((size_t)n, strlen(buf));
        assert_int_equal(buf[n - 1], '\n');
        sf_can_frame_t g;
        assert_int_equal(sf_candump_parse(buf, &g), SF_OK);
        assert_int_equal(g.host_t_us, f.host_t_us);
        assert_int_equal(g.id, f.id);
        assert_int_equal(g.extended, f.extended);
        assert_int_equal(g.remote, f.remote);
        assert_int_equal(g.dlc, f.dlc);
        assert_memory_equal(g.data, f.data, f.dlc);
    }
}

static void test_format_exact_text_and_small_buffer(void **state)
{
    (void)state;
    sf_can_frame_t f = {.host_t_us = 1700000000123456LL, .id = 0x100, .dlc = 2, .data = {0xAB, 0x01}};
    char buf[80];
    assert_int_equal(sf_candump_format(&f, "can0", buf, sizeof buf), 34);
    assert_string_equal(buf, "(1700000000.123456) can0 100#AB01\n");
    f.extended = true;
    f.id = 0x1ABCDEF;
    assert_int_equal(sf_candump_format(&f, "can0", buf, sizeof buf), 39);
    assert_string_equal(buf, "(1700000000.123456) can0 01ABCDEF#AB01\n");
    char small[10];
    assert_int_equal(sf_candump_format(&f, "can0", small, sizeof small), SF_EINVAL);
}

/* ---- sf_can_input on files ---- */

static void write_temp(char *const path, const char *const text)
{
    strcpy(path, "/tmp/sf_test_candump_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    const size_t len = strlen(text);
    assert_int_equal(write(fd, text, len), (ssize_t)len);
    close(fd);
}

static void test_input_file_good_blank_and_garbage(void **state)
{
    (void)state;
    char path[64];
    write_temp(path,
               "(1.000000) can0 080#0102030405060708\n" /* 1 */
               "\n"                                      /* 2 blank */
               "garbage\n"                               /* 3 */
               "(2.000000) can0 100#00\r\n"              /* 4 */
               "   \n"                                   /* 5 spaces: not blank, bad */
               "(3.000000) can0 100##00\n"               /* 6 CAN FD, an odd digit */
               "\r\n"                                    /* 7 blank */
               "(3.500000) can0 101##4001122 T\n"        /* 8 CAN FD, 3 bytes, a direction flag */
               "(4.000000) can0 12345678#R");            /* 9, no final newline */
    sf_can_input_t in;
    char err[256] = "";
    assert_int_equal(sf_can_input_open(&in, path, err, sizeof err), SF_OK);
    sf_can_frame_t f;

    assert_int_equal(sf_can_input_next(&in, &f), 1);
    assert_int_equal(in.line_no, 1);
    assert_int_equal(f.host_t_us, 1000000);
    assert_int_equal(f.dlc, 8);

    assert_int_equal(sf_can_input_next(&in, &f), SF_ESYNTAX);
    assert_int_equal(in.line_no, 3);
    assert_string_equal(in.line, "garbage");

    assert_int_equal(sf_can_input_next(&in, &f), 1);
    assert_int_equal(in.line_no, 4);
    assert_int_equal(f.host_t_us, 2000000);
    assert_int_equal(f.id, 0x100);

    assert_int_equal(sf_can_input_next(&in, &f), SF_ESYNTAX);
    assert_int_equal(in.line_no, 5);

    assert_int_equal(sf_can_input_next(&in, &f), SF_ESYNTAX);
    assert_int_equal(in.line_no, 6);
    assert_string_equal(in.line, "(3.000000) can0 100##00");

    assert_int_equal(sf_can_input_next(&in, &f), SF_ENOTCLASSIC);
    assert_int_equal(in.line_no, 8);
    assert_int_equal(f.host_t_us, 3500000);
    assert_int_equal(f.id, 0x101);

    assert_int_equal(sf_can_input_next(&in, &f), 1);
    assert_int_equal(in.line_no, 9);
    assert_true(f.extended);
    assert_true(f.remote);

    assert_int_equal(sf_can_input_next(&in, &f), 0);
    assert_int_equal(sf_can_input_next(&in, &f), 0); /* EOF stays EOF */
    sf_can_input_close(&in);
    unlink(path);
}

/* GIVEN a file of len bytes whose line 1 is bad and line 2 a frame at good_t_us, THEN the input
 * says so, line by line, and ends. */
static void bad_line_then_good_line(const char *const text, const size_t len, const int64_t good_t_us)
{
    char path[64];
    strcpy(path, "/tmp/sf_test_candump_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, text, len), (ssize_t)len);
    close(fd);
    sf_can_input_t in;
    assert_int_equal(sf_can_input_open(&in, path, NULL, 0), SF_OK);
    sf_can_frame_t f;
    assert_int_equal(sf_can_input_next(&in, &f), SF_ESYNTAX);
    assert_int_equal(in.line_no, 1);
    assert_int_equal(sf_can_input_next(&in, &f), 1);
    assert_int_equal(in.line_no, 2);
    assert_int_equal(f.host_t_us, good_t_us);
    assert_int_equal(sf_can_input_next(&in, &f), 0);
    sf_can_input_close(&in);
    unlink(path);
}

static void test_input_overlong_line_is_skipped(void **state)
{
    (void)state;
    char text[2048];
    memset(text, 'x', 1500);
    strcpy(text + 1500, "\n(5.000000) can0 100#01\n");
    bad_line_then_good_line(text, strlen(text), 5000000);
}

/* Regression for "a NUL swallows the next line": with fgets + strlen, a line holding a NUL looked cut
 * short and its "rest" — the whole next line — was skipped unread. Now only that line is bad. */
static void test_input_nul_inside_a_line_spoils_that_line_only(void **state)
{
    (void)state;
    const char text[] = "(1.000000) can0 100#00\0junk\n(2.000000) can0 100#01\n";
    bad_line_then_good_line(text, sizeof text - 1, 2000000);
}

#define N_CHUNK_LINES 6000

/* Line i's time and length: every third of the shape a board's replay has (10-digit seconds, 8 bytes:
 * the parser's fast path), the others of i % 9 bytes. */
static int64_t numbered_t_us(const int i)
{
    return (i % 3 == 0 ? 1700000000000000LL : 0) + 1000000LL * i + i;
}

static uint8_t numbered_dlc(const int i)
{
    return i % 3 == 0 ? 8 : (uint8_t)(i % 9);
}

/* Line i of the chunk-boundary test: a frame of numbered_dlc(i) bytes at numbered_t_us(i), every 7th
 * line CRLF, every 11th followed by a blank line; the text into buf, its length. */
static size_t numbered_line(const int i, char *const buf, const size_t size)
{
    sf_can_frame_t f = {.host_t_us = numbered_t_us(i), .id = (uint32_t)i & 0x7FFu, .dlc = numbered_dlc(i)};
    for (size_t k = 0; k < f.dlc && k < sizeof f.data; k++) { /* the bound: gcc 12 -O3 -Wstringop-overflow */
        f.data[k] = (uint8_t)((size_t)i + k);
    }
    int n = sf_candump_format(&f, i % 2 ? "can0" : "a-much-longer-interface-name", buf, size);
    assert_true(n > 0);
    if (i % 7 == 0) {
        strcpy(buf + n - 1, "\r\n");
        n++;
    }
    if (i % 11 == 0) {
        strcpy(buf + n, "\n");
        n++;
    }
    return (size_t)n;
}

static void read_numbered_lines(sf_can_input_t *const in)
{
    long line_no = 0;
    for (int i = 0; i < N_CHUNK_LINES; i++) {
        sf_can_frame_t f;
        assert_int_equal(sf_can_input_next(in, &f), 1);
        line_no += 1 + (i > 0 && (i - 1) % 11 == 0); /* the blank line after the previous one */
        assert_int_equal(in->line_no, line_no);
        assert_int_equal(f.host_t_us, numbered_t_us(i));
        assert_int_equal(f.id, (uint32_t)i & 0x7FFu);
        assert_int_equal(f.dlc, numbered_dlc(i));
        for (int k = 0; k < f.dlc; k++) {
            assert_int_equal(f.data[k], (uint8_t)(i + k));
        }
    }
    sf_can_frame_t f;
    assert_int_equal(sf_can_input_next(in, &f), 0);
}

/* Lines that straddle the reader's 64 KiB chunks, from a file and from a pipe fed a few bytes at a
 * time (read(2) returns what the pipe holds: partial lines wait for their rest). */
static void test_input_lines_across_chunks_from_a_file_and_a_pipe(void **state)
{
    (void)state;
    static char text[N_CHUNK_LINES * 80];
    size_t len = 0;
    for (int i = 0; i < N_CHUNK_LINES; i++) {
        len += numbered_line(i, text + len, sizeof text - len);
    }
    assert_true(len > 4 * SF_CAN_INPUT_CHUNK_BYTES);
    char path[64];
    write_temp(path, text);
    sf_can_input_t in;
    assert_int_equal(sf_can_input_open(&in, path, NULL, 0), SF_OK);
    read_numbered_lines(&in);
    sf_can_input_close(&in);
    unlink(path);

    int fds[2];
    assert_int_equal(pipe(fds), 0);
    const pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        close(fds[0]);
        for (size_t at = 0; at < len;) {
            const size_t piece = 1 + (at * 7919) % 97;
            const ssize_t n = write(fds[1], text + at, piece < len - at ? piece : len - at);
            if (n <= 0) {
                _exit(1);
            }
            at += (size_t)n;
        }
        _exit(0);
    }
    close(fds[1]);
    sf_can_input_t p = {.kind = sf_can_input_file, .file = fdopen(fds[0], "r"), .fd = -1};
    assert_non_null(p.file);
    read_numbered_lines(&p);
    sf_can_input_close(&p);
    int status = -1;
    assert_int_equal(waitpid(child, &status, 0), child);
    assert_int_equal(status, 0);
}

static void test_input_missing_file(void **state)
{
    (void)state;
    sf_can_input_t in;
    char err[256] = "";
    assert_int_equal(sf_can_input_open(&in, "/nonexistent/dir/log.candump", err, sizeof err), SF_ENOENT);
    assert_non_null(strstr(err, "/nonexistent/dir/log.candump"));
}

static void test_input_empty_spec(void **state)
{
    (void)state;
    sf_can_input_t in;
    char err[256] = "";
    assert_int_equal(sf_can_input_open(&in, "", err, sizeof err), SF_EINVAL);
    assert_true(strlen(err) > 0);
}

static void test_input_socketcan_nonexistent(void **state)
{
    (void)state;
    sf_can_input_t in;
    char err[256] = "";
    const int rc = sf_can_input_open(&in, "socketcan:sfnonexist0", err, sizeof err);
    if (rc == SF_OK) {
        sf_can_input_close(&in);
        fail_msg("opened a CAN interface that does not exist");
    }
    /* no AF_CAN in this kernel → SF_EUNSUPPORTED; AF_CAN but no such interface → SF_ENOENT */
    if (rc != SF_EUNSUPPORTED && rc != SF_ENOENT) {
        fail_msg("got %d (%s), want SF_EUNSUPPORTED or SF_ENOENT", rc, sf_strerror(rc));
    }
    assert_true(strlen(err) > 0);
    assert_non_null(strstr(err, "socketcan:sfnonexist0"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_standard_id_8_bytes),
        cmocka_unit_test(test_parse_extended_id),
        cmocka_unit_test(test_parse_remote),
        cmocka_unit_test(test_parse_every_length),
        cmocka_unit_test(test_parse_line_endings),
        cmocka_unit_test(test_parse_garbage_is_syntax_error),
        cmocka_unit_test(test_parse_direction_flag_is_the_same_frame),
        cmocka_unit_test(test_parse_can_fd_lines),
        cmocka_unit_test(test_parse_null_is_einval),
        cmocka_unit_test(test_format_parse_round_trip),
        cmocka_unit_test(test_format_exact_text_and_small_buffer),
        cmocka_unit_test(test_input_file_good_blank_and_garbage),
        cmocka_unit_test(test_input_overlong_line_is_skipped),
        cmocka_unit_test(test_input_nul_inside_a_line_spoils_that_line_only),
        cmocka_unit_test(test_input_lines_across_chunks_from_a_file_and_a_pipe),
        cmocka_unit_test(test_input_missing_file),
        cmocka_unit_test(test_input_empty_spec),
        cmocka_unit_test(test_input_socketcan_nonexistent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
