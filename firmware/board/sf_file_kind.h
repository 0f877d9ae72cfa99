/* sf_file_kind.h — refuse what is not a file where a file is expected (a device or a directory given
 * as an input, a config or a site file).
 *
 * A config, a site file, a candump or an LCM log read from /dev/zero never ends, and a directory
 * "opens" and then fails obscurely: each path is checked by stat() before it is opened. Regular files
 * pass; a FIFO (a pipe, `<(...)`) passes where the caller allows a stream; a directory, a character
 * or block device or a socket is refused with a message naming the path and what it is.
 * Standard input ("-") is not a path and is never checked here. Cost: one stat(). */
#ifndef SF_FILE_KIND_H
#define SF_FILE_KIND_H

#include <stdbool.h>
#include <stddef.h>

/* SF_OK, SF_ENOENT (no such file) or SF_EIO (cannot stat, or not a file: "PATH: config is a
 * directory, not a file"), the "cannot read" of every loader's contract; what names the role
 * ("config", "site file", ...) in the message. */
int sf_file_check(const char *path, const char *what, bool allow_fifo, char *err_text, size_t err_size);

/* True when fd is open on a regular file, whose reads never wait for a writer (the log may then be
 * written by the reading thread, sf_lcm_out.h caller_writes); false for a pipe, a FIFO, a terminal,
 * a socket, or fd < 0. Cost: one fstat(). */
bool sf_file_is_regular(int fd);

#endif
