/* sf_candump.c — strict reader and writer of candump -L lines (see sf_candump.h). */
#include "sf_candump.h"

#include <stdio.h>
#include <string.h>

#include "sf_error.h"

static int hex_value(const char c)
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

static int is_space(const char c)
{
    return c == ' ' || c == '\t';
}

int sf_candump_parse(const char *line, sf_can_frame_t *const frame)
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
    if (ndig != 6 || *p++ != ')' || !is_space(*p)) {
        return SF_ESYNTAX;
    }
    while (is_space(*p)) {
        p++;
    }
    /* interface name */
    const char *const iface = p;
    while (*p != '\0' && !is_space(*p)) {
        p++;
    }
    if (p == iface || !is_space(*p)) {
        return SF_ESYNTAX;
    }
    while (is_space(*p)) {
        p++;
    }
    /* id#data */
    uint32_t id = 0;
    ndig = 0;
    int h;
    while ((h = hex_value(*p)) >= 0) {
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
    if (*p == 'R') {
        f.remote = true;
        p++;
    } else {
        int n = 0;
        int hi;
        while ((hi = hex_value(p[0])) >= 0) {
            const int lo = hex_value(p[1]);
            if (lo < 0 || n >= 8) {
                return SF_ESYNTAX;
            }
            f.data[n++] = (uint8_t)((hi << 4) | lo);
            p += 2;
        }
        f.dlc = (uint8_t)n;
    }
    while (is_space(*p) || *p == '\r' || *p == '\n') {
        p++;
    }
    if (*p != '\0') {
        return SF_ESYNTAX;
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
