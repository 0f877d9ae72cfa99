/* sf_can_input.c — candump file / stdin and SocketCAN readers (see sf_can_input.h). */
#define _GNU_SOURCE
#include "sf_can_input.h"

#include <errno.h>
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

int sf_can_input_next(sf_can_input_t *const in, sf_can_frame_t *const frame)
{
    if (in->kind == sf_can_input_socketcan) {
        return next_socketcan(in, frame);
    }
    for (;;) {
        if (fgets(in->line, sizeof in->line, in->file) == NULL) {
            if (ferror(in->file) && errno == EINTR) {
                clearerr(in->file);
                return SF_EINTR; /* a signal: the caller decides whether to stop */
            }
            return ferror(in->file) ? SF_EIO : 0;
        }
        in->line_no++;
        size_t len = strlen(in->line);
        const int whole = len > 0 && in->line[len - 1] == '\n';
        if (!whole && !feof(in->file)) {
            /* Longer than any candump line: skip the rest of it and report it as bad syntax. */
            int c;
            while ((c = fgetc(in->file)) != EOF && c != '\n') {
            }
            return SF_ESYNTAX;
        }
        while (len > 0 && (in->line[len - 1] == '\n' || in->line[len - 1] == '\r')) {
            in->line[--len] = '\0';
        }
        if (len == 0) {
            continue; /* blank lines are not frames */
        }
        return sf_candump_parse(in->line, frame) == SF_OK ? 1 : SF_ESYNTAX;
    }
}

void sf_can_input_close(sf_can_input_t *const in)
{
    if (in->file != NULL && in->file != stdin) {
        fclose(in->file);
    }
    in->file = NULL;
    /* Only a socket this input opened: a zeroed, never-opened input has fd 0, which is stdin (the
     * --replay bug that closed a CAN input it never opened). */
    if (in->kind == sf_can_input_socketcan && in->fd >= 0) {
        close(in->fd);
    }
    in->fd = -1;
}
