/* sf_workspace.c — one block, five arrays (see sf_workspace.h). The doubles come first so that every
 * array is aligned for its type. */
#include "sf_workspace.h"

#include <stdlib.h>

#include "sf_error.h"

_Static_assert(SF_FINGERPRINT_WS_BYTES_PER_RP == 32, "sf_workspace.h promises 32 bytes per reference point");

int sf_workspace_alloc(const sf_radiomap_t *const map, sf_fingerprint_workspace_t *const ws, void **const memory)
{
    const size_t n = (size_t)(map->n_rp > 0 ? map->n_rp : 1);
    unsigned char *const m = calloc(n, SF_FINGERPRINT_WS_BYTES_PER_RP);
    if (m == NULL) {
        return SF_EIO;
    }
    ws->n_rp = (int32_t)n;
    ws->rp_fill_sq_db2 = (double *)(void *)m;
    ws->rp_miss_loglik = (double *)(void *)(m + n * sizeof(double));
    ws->acc = (double *)(void *)(m + 2 * n * sizeof(double));
    ws->n_common = (int32_t *)(void *)(m + 3 * n * sizeof(double));
    ws->touched = (int32_t *)(void *)(m + 3 * n * sizeof(double) + n * sizeof(int32_t));
    *memory = m;
    return SF_OK;
}

void sf_workspace_free(void *const memory)
{
    free(memory);
}
