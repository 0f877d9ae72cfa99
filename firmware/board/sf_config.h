/* sf_config.h — the `key = value` INI config file (parsed by inih) into sf_params_t.
 *
 *     [pdr]
 *     stride_m = 0.72
 *
 * Keys are the rows of SF_PARAM_LIST (firmware/core/sf_params.h). Every key has a default; an unknown
 * section or key, a value that is not a number, or one outside the row's range stops start-up with a
 * message naming the file and line. So does a line longer than inih's line buffer (the library's
 * INI_MAX_LINE, 200 bytes in Debian's libinih: 199 characters and the newline), which inih itself
 * would split and misread, and a line holding a NUL byte. A path that is a directory or device
 * (sf_file_kind.h) is refused before it is opened; a FIFO is read. */
#ifndef SF_CONFIG_H
#define SF_CONFIG_H

#include <stddef.h>

#include "sf_params.h"

/* Applies the file on top of *params. SF_OK, SF_ENOENT / SF_EIO (cannot read, not a file), SF_ESYNTAX
 * (bad or over-long line, unknown key) or SF_ERANGE (value out of range); err_text gets
 * "file:line: what". */
int sf_config_load(const char *path, sf_params_t *params, char *err_text, size_t err_size);

/* Applies one "section.name=value" override (the --set option); the value is read in place, of any
 * length. Same codes as sf_config_load. */
int sf_config_set(const char *assignment, sf_params_t *params, char *err_text, size_t err_size);

#endif
