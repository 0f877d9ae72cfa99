/* fuzz_site.c — the site loader's from-memory core (sf_site_parse) on any bytes, twice: as given
 * (the header checks), and with the header's length and CRC-32 repaired so that the fuzzer's
 * mutations reach the payload walk, the generated decode and the field checks behind the CRC.
 * Reference checks: only the documented codes; a failure leaves an empty store and a message; a
 * loaded site passes sf_radiomap_check. */
#include <string.h>

#include "sf_error.h"
#include "sf_fuzz.h"
#include "sf_radiomap.h"
#include "sf_site.h"

static void parse(const uint8_t *const data, const size_t size)
{
    sf_site_store_t store;
    sf_site_t site;
    char err[512];
    const int rc = sf_site_parse(data, size, "fuzz.sfsite", &store, &site, err, sizeof err);
    SF_FUZZ_CHECK(rc == SF_OK || rc == SF_ESYNTAX || rc == SF_ERANGE || rc == SF_EIO);
    if (rc == SF_OK) {
        const char *what = NULL;
        SF_FUZZ_CHECK(sf_radiomap_check(&site.radiomap, &what) == SF_OK);
    } else {
        SF_FUZZ_CHECK(store.loaded == 0 && store.ap_first == NULL && strlen(err) > 0);
    }
    sf_site_store_free(&store);
}

static void put_le32(uint8_t *const p, const uint32_t v)
{
    for (int i = 0; i < 4; i++) {
        p[i] = (uint8_t)(v >> (8 * i));
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *const data, const size_t size)
{
    parse(data, size);
    if (size >= SF_SITE_HEADER_SIZE && size - SF_SITE_HEADER_SIZE <= SF_SITE_MAX_PAYLOAD) {
        uint8_t *const copy = malloc(size);
        if (copy == NULL) {
            return 0;
        }
        memcpy(copy, data, size);
        const size_t payload = size - SF_SITE_HEADER_SIZE;
        put_le32(copy + 12, (uint32_t)payload);
        put_le32(copy + 16, sf_site_crc32(copy + SF_SITE_HEADER_SIZE, payload));
        parse(copy, size);
        free(copy);
    }
    return 0;
}
