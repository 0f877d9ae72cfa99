/* sf_log_file.c — an LCM event log file: O_EXCL|O_NOFOLLOW .part, whole-event writes, rename on
 * close (see sf_log_file.h). */
#define _GNU_SOURCE
#include "sf_log_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include "sf_error.h"

#define LCMLOG_SUFFIX ".lcmlog"

/* Big-endian stores, one byte swap and one store each where the compiler offers the builtin (GCC
 * spelled the shifts out as ~120 instructions per event header, every event of the log); the
 * portable shifts elsewhere. */
static void put_be32(unsigned char *const p, const uint32_t v)
{
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    const uint32_t be = __builtin_bswap32(v);
    memcpy(p, &be, sizeof be);
#else
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
#endif
}

static void put_be64(unsigned char *const p, const uint64_t v)
{
    put_be32(p, (uint32_t)(v >> 32));
    put_be32(p + 4, (uint32_t)v);
}

void sf_log_file_put_header(unsigned char *const head, const int64_t number, const int64_t timestamp_us,
                            const size_t channel_len, const size_t size)
{
    put_be32(head, SF_EVENTLOG_MAGIC);
    put_be64(head + 4, (uint64_t)number);
    put_be64(head + 12, (uint64_t)timestamp_us);
    put_be32(head + 20, (uint32_t)channel_len);
    put_be32(head + 24, (uint32_t)size);
}

size_t sf_log_file_event_bytes(const unsigned char *const head)
{
    const uint32_t channel_len = (uint32_t)head[20] << 24 | (uint32_t)head[21] << 16 | (uint32_t)head[22] << 8 | head[23];
    const uint32_t size = (uint32_t)head[24] << 24 | (uint32_t)head[25] << 16 | (uint32_t)head[26] << 8 | head[27];
    return SF_LOG_FILE_EVENT_OVERHEAD + (size_t)channel_len + (size_t)size;
}

/* A file we may truncate under --force: a regular file with no other name (a hard link planted at
 * the .part name would otherwise let us truncate someone else's file). Looked at through the open fd,
 * before any byte of it changes; err says why not. */
static bool safe_to_reuse(const int fd, const char *const part_path, char *const err, const size_t err_size)
{
    struct stat st;
    if (fstat(fd, &st) != 0) {
        snprintf(err, err_size, "%s: cannot stat: %s; refused, not truncated", part_path, strerror(errno));
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, err_size, "%s: not a regular file; refused, not truncated", part_path);
        return false;
    }
    if (st.st_nlink != 1) {
        snprintf(err, err_size, "%s: %ju links (a hard link to another file); refused, not truncated",
                 part_path, (uintmax_t)st.st_nlink);
        return false;
    }
    return true;
}

int sf_log_file_open(sf_log_file_t *const f, const char *const path, const bool force, char *const err,
                     const size_t err_size)
{
    if (f == NULL || path == NULL || path[0] == '\0') {
        return SF_EINVAL;
    }
    memset(f, 0, sizeof *f);
    f->fd = -1;
    f->force = force;
    if ((size_t)snprintf(f->path, sizeof f->path, "%s", path) >= sizeof f->path ||
        (size_t)snprintf(f->part_path, sizeof f->part_path, "%s%s", path, SF_LOG_FILE_PART_SUFFIX) >=
            sizeof f->part_path) {
        snprintf(err, err_size, "%.200s...: log path too long", path);
        return SF_EINVAL;
    }
    struct stat st;
    if (!force && lstat(path, &st) == 0) {
        snprintf(err, err_size, "%s: exists; not overwritten (--force replaces it)", path);
        errno = EEXIST;
        return SF_EIO;
    }
    /* O_NONBLOCK: a FIFO planted at the name must not hang the open (it is refused below). */
    /* --force: no O_TRUNC here, the file is emptied only once safe_to_reuse has looked at it. */
    const int flags = O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK | (force ? 0 : O_EXCL);
    const int fd = open(f->part_path, flags, 0666);
    if (fd < 0) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot create: %s%s", f->part_path, strerror(e),
                 e == ELOOP   ? " (a symlink: never followed)"
                 : e == EEXIST ? " (not overwritten; --force replaces it)"
                               : "");
        errno = e;
        return SF_EIO;
    }
    if (force && !safe_to_reuse(fd, f->part_path, err, err_size)) {
        close(fd);
        errno = EEXIST;
        return SF_EIO;
    }
    if (force && ftruncate(fd, 0) != 0) {
        const int e = errno;
        close(fd);
        snprintf(err, err_size, "%s: cannot truncate: %s", f->part_path, strerror(e));
        errno = e;
        return SF_EIO;
    }
    (void)fcntl(fd, F_SETFL, 0);
    f->fd = fd;
    return SF_OK;
}

/* Writes the n_iov buffers at f->offset with as many pwritev calls as it takes; on failure the file
 * is truncated back to f->offset (a partial event is undone: the file stays whole) and errno says why.
 * f->offset is the caller's to advance. */
static int write_at_end(sf_log_file_t *const f, struct iovec *next, int n_iov)
{
    uint64_t at = f->offset;
    while (n_iov > 0) {
        const ssize_t n = pwritev(f->fd, next, n_iov, (off_t)at);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            const int e = n == 0 ? ENOSPC : errno;
            (void)ftruncate(f->fd, (off_t)f->offset);
            errno = e;
            return SF_EIO;
        }
        at += (uint64_t)n;
        size_t left = (size_t)n;
        while (n_iov > 0 && left >= next->iov_len) {
            left -= next->iov_len;
            next++;
            n_iov--;
        }
        if (n_iov > 0) {
            next->iov_base = (char *)next->iov_base + left;
            next->iov_len -= left;
        }
    }
    return SF_OK;
}

int sf_log_file_write(sf_log_file_t *const f, const char *const channel, const int64_t timestamp_us,
                      const void *const data, const size_t size)
{
    if (f == NULL || f->fd < 0 || channel == NULL || (data == NULL && size > 0) || size > INT32_MAX) {
        return SF_EINVAL;
    }
    const size_t channel_len = strlen(channel);
    unsigned char head[SF_LOG_FILE_EVENT_OVERHEAD];
    sf_log_file_put_header(head, f->next_event, timestamp_us, channel_len, size);
    /* DEVIATION: struct iovec's base is non-const; pwritev only reads it. */
    struct iovec v[3] = {{head, sizeof head}, {(void *)channel, channel_len}, {(void *)data, size}};
    const int rc = write_at_end(f, v, size > 0 ? 3 : 2);
    if (rc != SF_OK) {
        return rc;
    }
    f->offset += sizeof head + channel_len + size;
    f->next_event++;
    return SF_OK;
}

int sf_log_file_append(sf_log_file_t *const f, uint8_t *const events, const size_t bytes, const uint64_t n_events)
{
    if (f == NULL || f->fd < 0 || (events == NULL && bytes > 0)) {
        return SF_EINVAL;
    }
    /* number the events as this file counts them (the number field is a placeholder until now) */
    size_t at = 0;
    for (uint64_t i = 0; i < n_events; i++) {
        if (bytes - at < SF_LOG_FILE_EVENT_OVERHEAD || sf_log_file_event_bytes(events + at) > bytes - at) {
            return SF_EINVAL;
        }
        put_be64(events + at + 4, (uint64_t)f->next_event + i);
        at += sf_log_file_event_bytes(events + at);
    }
    if (at != bytes) {
        return SF_EINVAL;
    }
    struct iovec v[1] = {{events, bytes}};
    const int rc = write_at_end(f, v, 1);
    if (rc != SF_OK) {
        return rc;
    }
    f->offset += bytes;
    f->next_event += (int64_t)n_events;
    return SF_OK;
}

int sf_log_file_sync(sf_log_file_t *const f)
{
    if (f == NULL || f->fd < 0) {
        return SF_EINVAL;
    }
    return fdatasync(f->fd) == 0 ? SF_OK : SF_EIO;
}

/* rename() that never replaces an existing file: RENAME_NOREPLACE, or link + unlink where the file
 * system lacks it. */
static int rename_noreplace(const char *const from, const char *const to)
{
    if (renameat2(AT_FDCWD, from, AT_FDCWD, to, RENAME_NOREPLACE) == 0) {
        return 0;
    }
    if (errno != EINVAL && errno != ENOSYS) {
        return -1;
    }
    if (link(from, to) != 0) {
        return -1;
    }
    return unlink(from);
}

int sf_log_file_close(sf_log_file_t *const f, char *const err, const size_t err_size)
{
    if (f == NULL || f->fd < 0) {
        return SF_OK;
    }
    int rc = SF_OK;
    if (fdatasync(f->fd) != 0) {
        snprintf(err, err_size, "%s: sync failed: %s", f->part_path, strerror(errno));
        rc = SF_EIO;
    }
    if (close(f->fd) != 0 && rc == SF_OK) {
        snprintf(err, err_size, "%s: close failed: %s", f->part_path, strerror(errno));
        rc = SF_EIO;
    }
    f->fd = -1;
    if ((f->force ? rename(f->part_path, f->path) : rename_noreplace(f->part_path, f->path)) != 0) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot rename to %s: %s (the log stays under its .part name)", f->part_path,
                 f->path, strerror(e));
        errno = e;
        return SF_EIO;
    }
    return rc;
}

void sf_log_file_discard(sf_log_file_t *const f)
{
    if (f == NULL || f->fd < 0) {
        return;
    }
    close(f->fd);
    f->fd = -1;
    (void)unlink(f->part_path);
}

int sf_log_file_rotated_name(char *const out, const size_t size, const char *const first, const unsigned index)
{
    if (out == NULL || first == NULL) {
        return SF_EINVAL;
    }
    const size_t len = strlen(first);
    const size_t n_suffix = strlen(LCMLOG_SUFFIX);
    const bool has_suffix = len > n_suffix && strcmp(first + len - n_suffix, LCMLOG_SUFFIX) == 0;
    const int stem = (int)(has_suffix ? len - n_suffix : len);
    const int n = index == 0 ? snprintf(out, size, "%s", first)
                             : snprintf(out, size, "%.*s.%03u%s", stem, first, index, has_suffix ? LCMLOG_SUFFIX : "");
    return n >= 0 && (size_t)n < size ? SF_OK : SF_EINVAL;
}

int sf_log_file_default_name(char *const out, const size_t size, const char *const dir,
                             const struct timespec *const now_utc, const long pid, const unsigned attempt)
{
    if (out == NULL || dir == NULL || now_utc == NULL) {
        return SF_EINVAL;
    }
    struct tm tm;
    char stamp[32];
    if (gmtime_r(&now_utc->tv_sec, &tm) == NULL || strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm) == 0) {
        return SF_EINVAL;
    }
    char counter[16] = "";
    if (attempt > 0) {
        snprintf(counter, sizeof counter, "-%u", attempt);
    }
    const int n = snprintf(out, size, "%s/stridefixd-%s-%06ld-%ld%s%s", dir, stamp, now_utc->tv_nsec / 1000, pid,
                           counter, LCMLOG_SUFFIX);
    return n >= 0 && (size_t)n < size ? SF_OK : SF_EINVAL;
}
