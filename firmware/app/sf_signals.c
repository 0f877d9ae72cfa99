/* sf_signals.c — flags set by SIGTERM/SIGINT/SIGHUP handlers (see sf_signals.h). */
#define _GNU_SOURCE
#include "sf_signals.h"

#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "sf_error.h"

_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "signal handlers need lock-free atomics");

static atomic_int stop_signal;
static atomic_int stop_seen; /* the main loop has left its reads: no more alarms */
static atomic_uint rotate_requests;

static void on_stop(const int sig)
{
    atomic_store(&stop_signal, sig);
    if (atomic_load(&stop_seen) == 0) {
        alarm(1);
    }
}

static void on_alarm(const int sig)
{
    (void)sig;
    if (atomic_load(&stop_signal) != 0 && atomic_load(&stop_seen) == 0) {
        alarm(1); /* the main loop has not stopped yet: interrupt its read again */
    }
}

static void on_hangup(const int sig)
{
    (void)sig;
    atomic_fetch_add(&rotate_requests, 1u);
}

static int install(const int sig, void (*const handler)(int), const int flags)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sa.sa_flags = flags;
    sigemptyset(&sa.sa_mask);
    return sigaction(sig, &sa, NULL) == 0 ? SF_OK : SF_EIO;
}

int sf_signals_install(void)
{
    if (install(SIGTERM, on_stop, 0) != SF_OK || install(SIGINT, on_stop, 0) != SF_OK ||
        install(SIGALRM, on_alarm, 0) != SF_OK || install(SIGHUP, on_hangup, SA_RESTART) != SF_OK) {
        return SF_EIO;
    }
    return SF_OK;
}

int sf_signals_stop_requested(void)
{
    return atomic_load(&stop_signal);
}

void sf_signals_input_done(void)
{
    atomic_store(&stop_seen, 1);
    alarm(0);
}

const atomic_uint *sf_signals_rotate_requests(void)
{
    return &rotate_requests;
}
