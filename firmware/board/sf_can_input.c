/* sf_can_input.c — candump file / stdin and SocketCAN readers (see sf_can_input.h). */
#define _GNU_SOURCE
#include "sf_can_input.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <unistd.h>

#include "sf_candump.h"
#include "sf_error.h"
#include "sf_file_kind.h"

#ifdef __linux__
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#endif

static int open_socketcan(sf_can_input_t *const in, const char *const iface, char *const err, const size_t n)
{
#ifdef __linux__
    const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (fd < 0) {
        const int e = errno;
        snprintf(err, n, "%s: cannot open a CAN socket: %s%s", in->name, strerror(e),
                 e == EAFNOSUPPORT ? " (this kernel has no AF_CAN; replay a candump file instead)" : "");
        return e == EAFNOSUPPORT ? SF_EUNSUPPORTED : SF_EIO;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    if (strlen(iface) >= sizeof ifr.ifr_name) { /* cut short, it could name another interface */
        snprintf(err, n, "%s: interface name longer than %zu characters", in->name, sizeof ifr.ifr_name - 1);
        close(fd);
        return SF_EINVAL;
    }
    snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", iface);
    if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        snprintf(err, n, "%s: no CAN interface '%s': %s", in->name, iface, strerror(errno));
        close(fd);
        return SF_ENOENT;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        snprintf(err, n, "%s: cannot bind: %s", in->name, strerror(errno));
        close(fd);
        return SF_EIO;
    }
    in->fd = fd;
    in->kind = sf_can_input_socketcan;
    return SF_OK;
#else
    (void)iface;
    snprintf(err, n, "%s: SocketCAN exists only on Linux", in->name);
    return SF_EUNSUPPORTED;
#endif
}

int sf_can_input_open(sf_can_input_t *const in, const char *const spec, char *err_text, size_t err_size)
{
    char dummy[8];
    if (err_text == NULL) {
        err_text = dummy;
        err_size = sizeof dummy;
    }
    err_text[0] = '\0';
    if (in == NULL || spec == NULL || spec[0] == '\0') {
        snprintf(err_text, err_size, "no input given");
        return SF_EINVAL;
    }
    memset(in, 0, sizeof *in);
    in->fd = -1;
    in->line = "";
    snprintf(in->name, sizeof in->name, "%s", spec);
    if (strncmp(spec, SF_CAN_INPUT_SOCKETCAN_PREFIX, strlen(SF_CAN_INPUT_SOCKETCAN_PREFIX)) == 0) {
        return open_socketcan(in, spec + strlen(SF_CAN_INPUT_SOCKETCAN_PREFIX), err_text, err_size);
    }
    in->kind = sf_can_input_file;
    if (strcmp(spec, "-") == 0) {
        in->file = stdin;
        snprintf(in->name, sizeof in->name, "<stdin>");
        return SF_OK;
    }
    /* a FIFO is a stream like stdin; a device (/dev/zero never ends) or a directory is refused */
    const int kind_rc = sf_file_check(spec, "input", true, err_text, err_size);
    if (kind_rc != SF_OK) {
        return kind_rc;
    }
    in->file = fopen(spec, "r");
    if (in->file == NULL) {
        const int e = errno;
        snprintf(err_text, err_size, "%s: cannot open: %s", spec, strerror(e));
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    return SF_OK;
}

static int next_socketcan(sf_can_input_t *const in, sf_can_frame_t *const frame)
{
#ifdef __linux__
    struct can_frame cf;
    for (;;) {
        const ssize_t n = read(in->fd, &cf, sizeof cf);
        if (n < 0 && errno == EINTR) {
            return SF_EINTR; /* a signal: the caller decides whether to stop */
        }
        if (n < 0) {
            return SF_EIO;
        }
        if (n == 0) {
            return 0;
        }
        if ((size_t)n < sizeof cf) {
            return SF_ESYNTAX; /* a CAN FD or partial read: not a classic frame */
        }
        break;
    }
    struct timeval tv;
    gettimeofday(&tv, NULL);
    memset(frame, 0, sizeof *frame);
    frame->host_t_us = (int64_t)tv.tv_sec * 1000000 + tv.tv_usec;
    frame->extended = (cf.can_id & CAN_EFF_FLAG) != 0;
    frame->remote = (cf.can_id & CAN_RTR_FLAG) != 0;
    frame->id = cf.can_id & (frame->extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    frame->dlc = cf.can_dlc > 8 ? 8 : cf.can_dlc;
    memcpy(frame->data, cf.data, frame->dlc);
    return 1;
#else
    (void)in;
    (void)frame;
    return SF_EUNSUPPORTED;
#endif
}

/* More input after the bytes not yet consumed (moved to the front first): 1 bytes read, 0 the end,
 * SF_EINTR or SF_EIO. A descriptor is read with read(2), which returns what a pipe has now (a
 * live-paced stdin is never waited on for a whole chunk); a stream without one (a memory stream)
 * with fread. */
static int fill(sf_can_input_t *const in)
{
    if (in->chunk_pos > 0) {
        memmove(in->chunk, in->chunk + in->chunk_pos, in->chunk_len - in->chunk_pos);
        in->chunk_len -= in->chunk_pos;
        in->chunk_pos = 0;
    }
    const size_t room = SF_CAN_INPUT_CHUNK_BYTES - in->chunk_len;
    const int fd = fileno(in->file);
    ssize_t n;
    if (fd >= 0) {
        n = read(fd, in->chunk + in->chunk_len, room);
    } else {
        n = (ssize_t)fread(in->chunk + in->chunk_len, 1, room, in->file);
        n = n == 0 && ferror(in->file) ? -1 : n;
    }
    if (n < 0) {
        return errno == EINTR ? SF_EINTR : SF_EIO; /* a signal: the caller decides whether to stop */
    }
    in->chunk_len += (size_t)n;
    return n > 0 ? 1 : 0;
}

/* The longest line taken whole (without its newline): what fgets into line[512] took, 510
 * characters and the newline; a longer one is skipped as bad syntax. */
#define LINE_MAX_CHARS (sizeof(((sf_can_input_t *)0)->overlong) - 2)

/* The rest of an overlong line, up to and with its newline: 1 done, or as fill. */
static int skip_rest(sf_can_input_t *const in)
{
    for (;;) {
        const char *const start = in->chunk + in->chunk_pos;
        const char *const nl = memchr(start, '\n', in->chunk_len - in->chunk_pos);
        if (nl != NULL) {
            in->chunk_pos += (size_t)(nl - start) + 1;
            in->skipping = false;
            return 1;
        }
        in->chunk_pos = in->chunk_len;
        const int rc = in->eof ? 0 : fill(in);
        if (rc <= 0) {
            in->eof |= rc == 0;
            in->skipping = rc != 0; /* interrupted: go on skipping at the next call */
            return rc == 0 ? 1 : rc;
        }
    }
}

/* The next line from the chunk buffer (a line per call, no copy): the candump replay read a million
 * lines an hour through fgets + strlen at ~170 instructions a line, here one memchr, and the line is
 * parsed where it lies (in->line points at it). Lines as fgets read them: blank ones skipped, trailing
 * CR/LF dropped, an overlong one bad syntax; a NUL inside a line makes it bad syntax (regression: with
 * fgets, strlen stopped at the NUL, the line looked cut short and the line after it was swallowed as
 * its rest). */
static int next_line(sf_can_input_t *const in, sf_can_frame_t *const frame)
{
    if (in->chunk == NULL) {
        in->chunk = malloc(SF_CAN_INPUT_CHUNK_BYTES + 1); /* + 1: the NUL after a last line without newline */
        if (in->chunk == NULL) {
            errno = ENOMEM;
            return SF_EIO;
        }
    }
    for (;;) {
        if (in->skipping) {
            const int rc = skip_rest(in);
            if (rc != 1) {
                return rc;
            }
        }
        char *const start = in->chunk + in->chunk_pos;
        const size_t avail = in->chunk_len - in->chunk_pos;
        char *nl = memchr(start, '\n', avail);
        if (nl == NULL && avail <= LINE_MAX_CHARS && !in->eof) {
            const int rc = fill(in);
            in->eof |= rc == 0;
            if (rc < 0) {
                return rc;
            }
            continue;
        }
        if (nl == NULL && avail == 0) {
            return 0; /* the end, and it stays the end */
        }
        size_t len = nl != NULL ? (size_t)(nl - start) : avail;
        in->line_no++;
        if (len > LINE_MAX_CHARS) { /* longer than any candump line: skipped, its start kept for the message */
            memcpy(in->overlong, start, sizeof in->overlong - 1);
            in->overlong[sizeof in->overlong - 1] = '\0';
            in->line = in->overlong;
            in->chunk_pos += nl != NULL ? len + 1 : avail;
            in->skipping = nl == NULL;
            return SF_ESYNTAX;
        }
        in->chunk_pos += nl != NULL ? len + 1 : len;
        while (len > 0 && start[len - 1] == '\r') {
            len--;
        }
        start[len] = '\0'; /* over its newline (or CR), or the byte after the chunk's last: parsed in place */
        in->line = start;
        if (len == 0) {
            continue; /* blank lines are not frames */
        }
        const int rc = sf_candump_parse_line(start, len, frame);
        return rc == SF_OK ? 1 : rc; /* SF_ESYNTAX, or SF_ENOTCLASSIC (a CAN FD line) */
    }
}

int sf_can_input_next(sf_can_input_t *const in, sf_can_frame_t *const frame)
{
    if (in->kind == sf_can_input_socketcan) {
        return next_socketcan(in, frame);
    }
    return next_line(in, frame);
}

void sf_can_input_close(sf_can_input_t *const in)
{
    if (in->file != NULL && in->file != stdin) {
        fclose(in->file);
    }
    in->file = NULL;
    free(in->chunk);
    in->chunk = NULL;
    /* Only a socket this input opened: a zeroed, never-opened input has fd 0, which is stdin (the
     * --replay bug that closed a CAN input it never opened). */
    if (in->kind == sf_can_input_socketcan && in->fd >= 0) {
        close(in->fd);
    }
    in->fd = -1;
}
