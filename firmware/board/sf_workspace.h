/* sf_workspace.h — the fingerprint matcher's workspace for a loaded site (sf_fingerprint.h): one heap
 * block of SF_FINGERPRINT_WS_BYTES_PER_RP (36) bytes per reference point, _PER_ENTRY (20) per map entry
 * and _PER_AP (8) per AP, laid out as the workspace's arrays, the pre-selection's included. Allocated
 * once at start-up (the board layer's only allocation besides the site file, the input and the log
 * queue); e.g. 10 000 RPs with 50 APs each → 10.4 MB. */
#ifndef SF_WORKSPACE_H
#define SF_WORKSPACE_H

#include "sf_fingerprint.h"
#include "sf_radiomap.h"

/* Sizes *ws to the map (at least one RP) and points its arrays into one zeroed block, returned in
 * *memory for sf_workspace_free. SF_OK, or SF_EIO when out of memory (ws untouched). */
int sf_workspace_alloc(const sf_radiomap_t *map, sf_fingerprint_workspace_t *ws, void **memory);

/* Frees the block of sf_workspace_alloc; NULL is fine. */
void sf_workspace_free(void *memory);

#endif
