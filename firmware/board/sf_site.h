/* sf_site.h — loads a site file (floors, map rotation, radio map; since version 2 also the
 * geo-reference, walls, ports and BLE beacons; since version 3 the multi-scheme controller's context
 * map: buildings, port extras and links, contexts, constellations) into the core's sf_site_t.
 *
 * File layout (written by analyzer/stridefix_analyzer/sitefile.py; header integers little-endian):
 *
 *     offset  size  field
 *          0     8  magic            "SFSITE\0\x01"
 *          8     4  format version   uint32, SF_SITE_FORMAT_VERSION
 *         12     4  payload length   uint32, file size − SF_SITE_HEADER_SIZE
 *         16     4  payload CRC-32   uint32, IEEE 802.3 (as zlib.crc32)
 *         20     4  reserved         uint32, 0
 *         24     n  payload          LCM encoding of stridefix.site_t (lcmtypes/stridefix/site_t.lcm),
 *                                    starting with the type hash
 *
 * Checks, in this order, each failing with a message "<path>: <what>" naming the values:
 *   1. SF_ESYNTAX — header: file ≥ 24 bytes, magic, version (1, 2: "rebuild it"), reserved = 0, payload length equal to
 *      the bytes after the header (truncation / trailing bytes), payload ≤ SF_SITE_MAX_PAYLOAD,
 *      CRC-32 of the payload;
 *   2. SF_ESYNTAX — payload: LCM type hash of site_t, every count and string fits in the payload,
 *      strings NUL-terminated, no trailing bytes; then the generated stridefix_site_t_decode;
 *   3. SF_ERANGE — fields, the same rules and order as sitefile.validate_site: finite map rotation
 *      (geo-reference in range when has_geo); n_floors ≥ 1 with finite, strictly increasing heights;
 *      BSSIDs in 0 … 2^48−1, strictly ascending; cell_size_m finite ≥ 0; RPs with finite positions,
 *      floor in lowest_floor … lowest_floor + n_floors − 1, rp_scans ≥ 1; entries with ap and rp
 *      indices in range (e.g. "entry 17: rp index 300 outside 0..99"), strictly sorted by (ap, rp),
 *      finite mean, finite std ≥ 0, 1 ≤ count ≤ rp_scans of the RP; then the version-2 rules
 *      (sf_site_v2.h: geo altitude and rotation when has_geo, walls, ports, beacons, BLE model),
 *      then the version-3 rules (sf_site_v3.h: outlines, port extras, links, contexts, constellations),
 *      then every numeric field within its physical range (sf_site_ranges.h: firmware/site_ranges.tsv,
 *      the table the Python reader checks too); finally sf_radiomap_check and the controller's
 *      sf_cls_check_map on the core view (so a site that loads is one the estimator attaches).
 * SF_ENOENT: no such file; SF_EIO: cannot read it (or out of memory); SF_EINVAL: NULL argument.
 *
 * Memory: this is the board layer, the one place that allocates. The store owns everything the view
 * points to (the decoded site_t's arrays and the ap_first index): the sf_site_t filled in stays
 * valid until sf_site_store_free(store). Cost: one read of the file, O(size) CRC and checks; memory
 * about twice the file while loading (file buffer + decoded arrays), then the decoded arrays plus
 * 4·(n_ap + 1) bytes. */
#ifndef SF_SITE_H
#define SF_SITE_H

#include <stddef.h>
#include <stdint.h>

#include "sf_radiomap.h"
#include "stridefix_site_t.h"

#define SF_SITE_HEADER_SIZE 24
#define SF_SITE_FORMAT_VERSION 3u /* version 1 and 2 files are refused: rebuild them */
#define SF_SITE_MAX_PAYLOAD (256u << 20) /* bytes; the same limit as sitefile.MAX_PAYLOAD_BYTES */

/* What a loaded site owns. Zero-initialise (or sf_site_store_free) before sf_site_load; read
 * msg.name / msg.source (and the other decoded fields) freely, change nothing. */
typedef struct {
    stridefix_site_t msg; /* the decoded site_t; its arrays were allocated by the LCM decoder */
    int32_t *ap_first;    /* [msg.n_ap + 1], malloc'd: AP-major index built from msg.entry_ap */
    int loaded;           /* 1 while msg holds decoded arrays */
} sf_site_store_t;

/* Reads, checks and decodes the site file at path. On SF_OK, *site is the core's view of the arrays
 * owned by *store. On failure *store is empty (nothing to free, though freeing is harmless), *site is
 * zeroed and err (if err_size > 0) holds "<path>: <what is wrong>". Returns SF_OK, SF_ENOENT, SF_EIO,
 * SF_ESYNTAX, SF_ERANGE or SF_EINVAL (see the list above). */
int sf_site_load(const char *path, sf_site_store_t *store, sf_site_t *site, char *err, size_t err_size);

/* The same checks on the bytes of a site file already in memory; name is used in messages. Never
 * SF_ENOENT / SF_EIO except for out of memory. */
int sf_site_parse(const uint8_t *data, size_t size, const char *name, sf_site_store_t *store,
                  sf_site_t *site, char *err, size_t err_size);

/* Frees what the store owns and zeroes it; a zeroed store is fine. Views built from it dangle. */
void sf_site_store_free(sf_site_store_t *store);

/* CRC-32 (IEEE 802.3, reflected, init and final xor 0xFFFFFFFF; = zlib.crc32) of n bytes. */
uint32_t sf_site_crc32(const void *data, size_t n);

#endif
