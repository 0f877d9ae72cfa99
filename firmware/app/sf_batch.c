/* sf_batch.c — `stridefixd --batch FILE` and the site its replays share (see sf_batch.h). */
#define _GNU_SOURCE
#include "sf_batch.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sf_error.h"
#include "sf_options.h"
#include "sf_workspace.h"

static struct {
    char path[SF_OPTIONS_PATH_MAX];
    struct stat st;
    sf_site_store_t store;
    sf_site_t site;
    int loaded;
    sf_fingerprint_workspace_t ws; /* for site.radiomap, as the last run left it; ws_memory NULL: none yet */
    void *ws_memory;
} cached;

int sf_batch_site(const char *const path, sf_site_t *const site, char *const err, const size_t err_size)
{
    struct stat st;
    const int have = stat(path, &st) == 0;
    if (cached.loaded && have && strcmp(cached.path, path) == 0 && st.st_size == cached.st.st_size &&
        st.st_mtim.tv_sec == cached.st.st_mtim.tv_sec && st.st_mtim.tv_nsec == cached.st.st_mtim.tv_nsec) {
        *site = cached.site;
        return SF_OK;
    }
    sf_batch_site_free();
    const int rc = sf_site_load(path, &cached.store, &cached.site, err, err_size);
    if (rc != SF_OK) {
        return rc;
    }
    cached.loaded = have && strlen(path) < sizeof cached.path;
    if (cached.loaded) {
        snprintf(cached.path, sizeof cached.path, "%s", path);
        cached.st = st;
    }
    *site = cached.site;
    return SF_OK;
}

void sf_batch_site_free(void)
{
    sf_workspace_free(cached.ws_memory);
    cached.ws_memory = NULL;
    memset(&cached.ws, 0, sizeof cached.ws);
    sf_site_store_free(&cached.store);
    cached.loaded = 0;
}

int sf_batch_workspace(const sf_radiomap_t *const map, sf_fingerprint_workspace_t *const ws)
{
    if (cached.ws_memory == NULL) {
        if (sf_workspace_alloc(map, &cached.ws, &cached.ws_memory) != SF_OK) {
            return SF_EIO;
        }
        cached.ws.reuse_prepared = true; /* the site's arrays are const while it is cached */
    }
    *ws = cached.ws;
    return SF_OK;
}

void sf_batch_workspace_keep(const sf_fingerprint_workspace_t *const ws)
{
    if (cached.ws_memory != NULL && ws->rp_fill_sq_db2 == cached.ws.rp_fill_sq_db2) {
        cached.ws = *ws; /* what it was prepared for, with the arrays it filled */
    }
}

int sf_batch_run(const char *const path, int (*const run)(int argc, char **argv), FILE *const out)
{
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        fprintf(stderr, "stridefixd: --batch %s: cannot open\n", path);
        return SF_EXIT_USAGE;
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t len;
    int rc = 0;
    while ((len = getline(&line, &cap, f)) >= 0) {
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r')) {
            line[--len] = '\0';
        }
        if (len == 0) {
            continue;
        }
        char *argv[SF_BATCH_MAX_ARGS + 2] = {"stridefixd"};
        int argc = 1;
        for (char *save = NULL, *tok = strtok_r(line, "\t", &save); tok != NULL; tok = strtok_r(NULL, "\t", &save)) {
            if (argc > SF_BATCH_MAX_ARGS) {
                fprintf(stderr, "stridefixd: --batch %s: a line of more than %d options\n", path, SF_BATCH_MAX_ARGS);
                rc = SF_EXIT_USAGE;
                break;
            }
            argv[argc++] = tok;
        }
        if (rc != 0) {
            break;
        }
        argv[argc] = NULL;
        fprintf(out, "%d\n", run(argc, argv));
        fflush(out);
    }
    free(line);
    fclose(f);
    return rc;
}
