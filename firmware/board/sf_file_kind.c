/* sf_file_kind.c — stat() a path and refuse directories, devices and sockets (see sf_file_kind.h). */
#define _POSIX_C_SOURCE 200809L /* stat(), S_ISSOCK */
#include "sf_file_kind.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sf_error.h"

/* What a refused file type is, in words; NULL for the types that pass. */
static const char *refused_kind(const mode_t mode, const bool allow_fifo)
{
    if (S_ISREG(mode) || (allow_fifo && S_ISFIFO(mode))) {
        return NULL;
    }
    return S_ISDIR(mode)    ? "a directory"
           : S_ISCHR(mode)  ? "a character device"
           : S_ISBLK(mode)  ? "a block device"
           : S_ISSOCK(mode) ? "a socket"
           : S_ISFIFO(mode) ? "a FIFO (a stream; this needs a regular file)"
                            : "not a regular file";
}

int sf_file_check(const char *const path, const char *const what, const bool allow_fifo, char *const err,
                  const size_t err_size)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open %s: %s", path, what, strerror(e));
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    const char *const kind = refused_kind(st.st_mode, allow_fifo);
    if (kind != NULL) {
        snprintf(err, err_size, "%s: %s is %s, not a file", path, what, kind);
        return SF_EIO; /* cannot be read as a file: the callers' "unreadable" */
    }
    return SF_OK;
}

bool sf_file_is_regular(const int fd)
{
    struct stat st;
    return fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
}
