/* sf_signals.h — stridefixd's signals: SIGTERM and SIGINT ask for a clean stop, SIGHUP for a log
 * rotation.
 *
 * The handlers only store into lock-free atomics (async-signal-safe). SIGTERM/SIGINT are installed
 * without SA_RESTART, so a blocking read of the input (stdin, SocketCAN) returns EINTR and the
 * main loop sees the stop; a signal that lands between the loop's check and the read would leave
 * that read blocked, so the stop handler also arms alarm(1), and SIGALRM (also without SA_RESTART)
 * re-arms it while a stop is pending: the read is interrupted within a second whatever the timing.
 * SIGHUP keeps SA_RESTART: a rotation must not cut a read short (stdio would lose the partial
 * line); the log writer thread watches the counter (sf_lcm_out's rotate_requests) by itself. */
#ifndef SF_SIGNALS_H
#define SF_SIGNALS_H

#include <stdatomic.h>

/* Installs the handlers. SF_OK or SF_EIO (sigaction failed; errno tells). */
int sf_signals_install(void);

/* The stop signal received (SIGTERM or SIGINT), or 0. */
int sf_signals_stop_requested(void);

/* The main loop reads no more input: the alarms stop (so they interrupt nothing during the close). */
void sf_signals_input_done(void);

/* Incremented by every SIGHUP. */
const atomic_uint *sf_signals_rotate_requests(void);

#endif
