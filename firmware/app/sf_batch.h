/* sf_batch.h — many replays in one stridefixd process (`stridefixd --batch FILE`), and the site file
 * they share.
 *
 * A benchmark's inner cross-validation replays thousands of short walks, most of them on a few
 * sites: as separate processes, each pays the process start and the site's read, CRC and decode
 * again (for a 20 s walk on a 1.5 MB site, more than the walk's own estimation). A batch file holds
 * one replay per line, its options as stridefixd takes them, separated by TAB characters (so a path
 * may hold spaces); each line runs exactly as `stridefixd OPTIONS` would, from a zeroed daemon and
 * freshly parsed parameters, and its exit status is printed to stdout, one line per replay, in
 * order. The only things runs share are a site already loaded from the same path (same size and
 * modification time) and the matcher's workspace prepared for it: the core only reads a site (const
 * everywhere), so a replay sees the same bytes either way, and the workspace is prepared again
 * whenever a parameter its preparation reads differs (sf_fingerprint_workspace_t.reuse_prepared). Messages of every run go to stderr as usual. */
#ifndef SF_BATCH_H
#define SF_BATCH_H

#include <stddef.h>
#include <stdio.h>

#include "sf_fingerprint.h"
#include "sf_site.h"

/* Runs run(argc, argv) for every line of path (argv[0] = "stridefixd"; blank lines skipped) and
 * prints each status to out. 0 when the file was read to its end, SF_EXIT_USAGE (with a message)
 * when it cannot be read or a line has more than SF_BATCH_MAX_ARGS options. */
#define SF_BATCH_MAX_ARGS 256
int sf_batch_run(const char *path, int (*run)(int argc, char **argv), FILE *out);

/* The site at path into *site: loaded (sf_site_load), or the copy loaded before from the same path,
 * size and modification time. SF_OK or sf_site_load's error (text in err). */
int sf_batch_site(const char *path, sf_site_t *site, char *err, size_t err_size);

/* Frees the site kept by sf_batch_site and its workspace (at exit). */
void sf_batch_site_free(void);

/* The matcher's workspace for the kept site's radio map (sf_workspace_alloc on first use, freed with
 * the site), as the last run left it: the core prepares it again only when the parameters it was
 * prepared with changed (reuse_prepared), so replays on one site prepare the map once. Pass the run's
 * copy back with sf_batch_workspace_keep when the run ends. SF_OK or SF_EIO (out of memory). */
int sf_batch_workspace(const sf_radiomap_t *map, sf_fingerprint_workspace_t *ws);
void sf_batch_workspace_keep(const sf_fingerprint_workspace_t *ws);

#endif
