/* sf_privilege.c — refuse a live input as root (see sf_privilege.h). */
#include "sf_privilege.h"

#include <stdio.h>
#include <unistd.h>

#include "sf_error.h"
#include "sf_input.h"

int sf_privilege_check(const char *const input_spec, const bool allow_root, char *const err,
                       const size_t err_size)
{
    if (geteuid() != 0 || allow_root || !sf_input_spec_is_live(input_spec)) {
        return SF_OK;
    }
    snprintf(err, err_size,
             "%s: refusing to read a live bus as root (run as an unprivileged user, e.g. the systemd unit "
             "in tools/systemd, or pass --allow-root)",
             input_spec);
    return SF_EINVAL;
}
