/* sf_workspace.c — one block for the workspace's arrays (see sf_workspace.h). The doubles come first so
 * that every array is aligned for its type. */
#include "sf_workspace.h"

#include <stdlib.h>

#include "sf_error.h"

_Static_assert(SF_FINGERPRINT_WS_BYTES_PER_RP == 36, "sf_workspace.h promises 36 bytes per reference point");
_Static_assert(SF_FINGERPRINT_WS_BYTES_PER_ENTRY == 20, "sf_workspace.h promises 20 bytes per map entry");

int sf_workspace_alloc(const sf_radiomap_t *const map, sf_fingerprint_workspace_t *const ws, void **const memory)
{
    const size_t n = (size_t)(map->n_rp > 0 ? map->n_rp : 1);
    const size_t e = (size_t)(map->n_entries > 0 ? map->n_entries : 1);
    const size_t a = (size_t)(map->n_ap > 0 ? map->n_ap : 1);
    const size_t bytes = n * SF_FINGERPRINT_WS_BYTES_PER_RP + sizeof(int32_t) + e * SF_FINGERPRINT_WS_BYTES_PER_ENTRY +
                         a * SF_FINGERPRINT_WS_BYTES_PER_AP;
    unsigned char *const m = calloc(1, bytes);
    if (m == NULL) {
        return SF_EIO;
    }
    double *d = (double *)(void *)m;
    ws->n_rp = (int32_t)n;
    ws->n_entries = (int32_t)e;
    ws->n_ap = (int32_t)a;
    ws->rp_fill_sq_db2 = d;
    ws->rp_miss_loglik = d += n;
    ws->acc = d += n;
    ws->rp_entry_level_db = d += n;
    ws->entry_level_db = d += e;
    ws->ap_query_w = d += e;
    int32_t *i = (int32_t *)(void *)(d + a);
    ws->n_common = i;
    ws->touched = i += n;
    ws->rp_entry_first = i += n; /* n + 1 */
    ws->rp_entry_ap = i + n + 1;
    *memory = m;
    return SF_OK;
}

void sf_workspace_free(void *const memory)
{
    free(memory);
}
