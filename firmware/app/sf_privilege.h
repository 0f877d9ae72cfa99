/* sf_privilege.h — least privilege: stridefixd does not read a live bus as root.
 *
 * A live input (SocketCAN, where stridefixd itself opens the bus: sf_input_spec_is_live) parses
 * frames that anyone on the bus can forge; a bug there must not run as root. So with euid 0 a
 * live input is refused unless --allow-root. File replays (candump files, lcmlog:) and stdin run
 * as any user: stdin's producer (e.g. `candump -L can0 |`) is what touches the bus and holds its
 * own privilege, and the SIL and the benches feed files and pipes. Nothing else needs root: the
 * log directory only needs to be writable and live LCM is an ordinary socket. */
#ifndef SF_PRIVILEGE_H
#define SF_PRIVILEGE_H

#include <stdbool.h>
#include <stddef.h>

/* SF_OK to go on, or SF_EINVAL (running as root on a live input without allow_root) with the
 * reason in err_text. */
int sf_privilege_check(const char *input_spec, bool allow_root, char *err_text, size_t err_size);

#endif
