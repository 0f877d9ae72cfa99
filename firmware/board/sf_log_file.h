/* sf_log_file.h — one LCM event log file on disk, from creation to its final name.
 *
 * A log is written as NAME.part and renamed to NAME when it is closed cleanly, so a file under its
 * final name is always complete, and a `.part` is one that a crash, SIGKILL or power loss cut short
 * (it still reads: every event is whole, see below). The `.part` is created with
 * O_CREAT|O_EXCL|O_NOFOLLOW: an existing file is never overwritten and a symlink never followed (a
 * link planted at a predictable name cannot redirect the log). With `force`, an existing `.part` is
 * reused (a killed run's) and the rename may replace an existing NAME; without it, an existing NAME
 * is refused at open and the rename never replaces one (RENAME_NOREPLACE). A reused `.part` is
 * opened without O_TRUNC, never through a symlink, and emptied only when fstat shows a regular file
 * with one link: a hard link planted there is refused (EEXIST) with its target untouched.
 *
 * Events are written in the LCM log format (28-byte header: sync word 0xEDA1DA01, event number,
 * timestamp [µs], channel length, data length, all big-endian; then the channel and the data),
 * numbered from 0 in each file as liblcm's writer numbers them, one pwritev() per call with no
 * user-space buffer: one event (sf_log_file_write), or a run of events the caller already laid out
 * in the format (sf_log_file_append: a batch costs one system call, not one per event). An event is
 * in the kernel when the call returns (so SIGKILL loses nothing written), on disk after
 * sf_log_file_sync. A write that fails (disk full) is undone by
 * truncating the file back to its last whole event, so the file holds exactly the events that
 * were reported written and later events follow them cleanly. liblcm offers no entry point that
 * takes a descriptor (lcm_eventlog_create opens with fopen, which can neither O_EXCL nor
 * O_NOFOLLOW, and its buffered writes cannot be undone), hence this writer; liblcm still reads the
 * files.
 *
 * Errors: SF_OK, SF_EINVAL, or SF_EIO with errno set (EEXIST: NAME or NAME.part exists; ELOOP: a
 * symlink; ENOSPC: disk full, ...) and, where an err buffer is taken, a one-line message. Not
 * thread-safe: one thread owns an open file. */
#ifndef SF_LOG_FILE_H
#define SF_LOG_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "sf_eventlog.h" /* the format: one definition for the reader and this writer */

#define SF_LOG_FILE_PATH_MAX 4096
#define SF_LOG_FILE_EVENT_OVERHEAD ((unsigned)SF_EVENTLOG_HEADER_SIZE) /* bytes of header per event */
#define SF_LOG_FILE_PART_SUFFIX ".part"

typedef struct {
    char path[SF_LOG_FILE_PATH_MAX];      /* the final name */
    char part_path[SF_LOG_FILE_PATH_MAX]; /* path + ".part", written until closed */
    int fd;                               /* -1 when not open */
    bool force;
    uint64_t offset;   /* bytes of whole events in the file */
    int64_t next_event; /* event number of the next event */
} sf_log_file_t;

/* Creates path.part (see the header comment for `force`). */
int sf_log_file_open(sf_log_file_t *f, const char *path, bool force, char *err, size_t err_size);

/* Appends one event, or leaves the file as it was and returns SF_EIO (errno says why). */
int sf_log_file_write(sf_log_file_t *f, const char *channel, int64_t timestamp_us, const void *data, size_t size);

/* Appends n_events whole events laid out in the file format (sf_log_file_put_header, then the channel
 * and the data), bytes in all: their event-number fields are overwritten with this file's numbering
 * (the caller may keep anything there until then), then one write; or the file is left as it was and
 * SF_EIO (errno says why). SF_EINVAL if the events do not add up to bytes. */
int sf_log_file_append(sf_log_file_t *f, uint8_t *events, size_t bytes, uint64_t n_events);

/* The 28-byte event header (the format in sf_eventlog.h) into head. */
void sf_log_file_put_header(unsigned char *head, int64_t number, int64_t timestamp_us, size_t channel_len,
                            size_t size);

/* The bytes of the whole event whose header is at head (header, channel and data). */
size_t sf_log_file_event_bytes(const unsigned char *head);

/* fdatasync: everything written so far survives power loss. */
int sf_log_file_sync(sf_log_file_t *f);

/* Syncs, closes and renames path.part to path. On a failed rename the .part stays (and is named
 * in err). Safe on a file that is not open (SF_OK). */
int sf_log_file_close(sf_log_file_t *f, char *err, size_t err_size);

/* Closes and removes path.part: for a file that holds nothing worth keeping. */
void sf_log_file_discard(sf_log_file_t *f);

/* The name of file `index` of a rotated log whose first file is `first`: index 0 is `first`
 * itself, index n > 0 inserts ".NNN" before a trailing ".lcmlog" (or appends it):
 * walk.lcmlog, walk.001.lcmlog, walk.002.lcmlog, ... SF_EINVAL if it does not fit. */
int sf_log_file_rotated_name(char *out, size_t size, const char *first, unsigned index);

/* The default name in dir: stridefixd-YYYYmmdd-HHMMSS-uuuuuu-PID[-N].lcmlog (UTC, microseconds,
 * the process id and, for attempt > 0, a counter): two daemons started in the same second get
 * different names, and a caller that meets an existing name (EEXIST) retries with attempt + 1. */
int sf_log_file_default_name(char *out, size_t size, const char *dir, const struct timespec *now_utc, long pid,
                             unsigned attempt);

#endif
