/* sf_log_writer.h — the writing side of sf_lcm_out (sf_lcm_out.h says what it promises): the log
 * files' lifecycle over events that arrive in runs already in the file format (sf_log_ring.h).
 *
 * For each run: plain events go to the file in one write (sf_log_file_append); an event that needs a
 * rule — a header to keep for the files to come, a rotation by size before it, no file open, or a
 * write-failure episode in progress — is handled on its own, as is every event of a run whose one
 * write failed, so that on a full disk exactly the events that fit are written and each other one is
 * dropped and counted (events and bytes) as if written one by one. The first failure of an episode is
 * reported on cfg->report, and so is the first event written after it (a sync that succeeds on a full
 * disk ends nothing: it only flushes what was written before). Every file starts with the header: a
 * rotated one with a copy, and a file whose header was dropped (a disk full from the start) gets a
 * copy before its first event once writes succeed. A file that nothing could be written to is removed
 * at close, not renamed to its final name as an empty log. Between runs, housekeeping closes a
 * file asked to rotate (rotate_requests, or the caller) or too old (rotate_s), else fdatasyncs when
 * fsync_interval_ms has passed since the last sync.
 *
 * One thread at a time writes (sf_lcm_out's writer thread, or its caller with caller_writes); the
 * counters are under the writer's own lock, so any thread may read them (sf_log_writer_counters) and
 * add the queue's drops and publish errors. Cost per plain event: its share of one system call plus
 * ~40 instructions (numbering, the run's walk). */
#ifndef SF_LOG_WRITER_H
#define SF_LOG_WRITER_H

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sf_lcm_out.h"
#include "sf_log_file.h"

typedef struct {
    const sf_lcm_out_config_t *cfg; /* the owner's, outliving the writer */
    char first_path[SF_LOG_FILE_PATH_MAX];
    sf_log_file_t file;
    unsigned file_index; /* the current file, or the last one while none is open */
    int64_t file_opened_us;
    int64_t last_sync_us;
    bool unsynced;
    unsigned rotations_seen;
    char *header_channel; /* copy of the latest header event; NULL if none */
    uint8_t *header_data;
    size_t header_size;
    bool file_has_header; /* the open file holds the header (or a copy of it) */
    bool failing;   /* inside a write-failure episode */
    int fail_errno; /* why the episode began */
    pthread_mutex_t lock; /* the counters and write_failed */
    sf_lcm_out_counters_t counters;
    bool write_failed;
} sf_log_writer_t;

/* Sets w up, no file open (cannot fail). */
void sf_log_writer_init(sf_log_writer_t *w, const sf_lcm_out_config_t *cfg);

/* Opens the first file, cfg->log_path: SF_OK, SF_EINVAL (no path), or as sf_log_file_open, with err. */
int sf_log_writer_open(sf_log_writer_t *w, char *err, size_t err_size);

/* Writes one run of whole events (the taken run of the ring; their number fields are overwritten). */
void sf_log_writer_events(sf_log_writer_t *w, uint8_t *events, size_t len);

/* Between runs: a rotation (asked for with `rotate`, by rotate_requests or due by age), else a sync. */
void sf_log_writer_housekeeping(sf_log_writer_t *w, bool rotate);

/* The queue dropped an event of `bytes` log bytes; a live publish failed. */
void sf_log_writer_dropped(sf_log_writer_t *w, uint64_t bytes);
void sf_log_writer_publish_failed(sf_log_writer_t *w);

void sf_log_writer_counters(sf_log_writer_t *w, sf_lcm_out_counters_t *counters);

/* Closes (and renames) the open file, if any: SF_OK, or SF_EIO when any write, sync or rename of the
 * writer's life failed (reported). Frees what the writer holds. */
int sf_log_writer_close(sf_log_writer_t *w);

#endif
