/* fuzz_config.c — the config parser (sf_config.c over inih) on any bytes: once as a whole config
 * file (sf_config_load reads a path: the input is written to a private temporary file), once as a
 * --set assignment (up to the first NUL or newline). Reference checks: only the documented codes,
 * a message on every failure, and every parameter stays inside its row's range (sf_param_table). */
#include <string.h>
#include <unistd.h>

#include "sf_config.h"
#include "sf_error.h"
#include "sf_fuzz.h"
#include "sf_params.h"

static char path[64];

static void check(const int rc, const sf_params_t *const params, const char *const err)
{
    SF_FUZZ_CHECK(rc == SF_OK || rc == SF_ESYNTAX || rc == SF_ERANGE || rc == SF_EIO || rc == SF_EINVAL);
    if (rc != SF_OK) {
        SF_FUZZ_CHECK(strlen(err) > 0);
    }
    for (size_t i = 0; i < sf_param_count; i++) {
        const double v = sf_param_get(params, &sf_param_table[i]);
        SF_FUZZ_CHECK(v >= sf_param_table[i].min_value && v <= sf_param_table[i].max_value);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *const data, const size_t size)
{
    if (path[0] == '\0') {
        snprintf(path, sizeof path, "/tmp/sf_fuzz_config_%ld.ini", (long)getpid());
    }
    FILE *const f = fopen(path, "wb");
    if (f == NULL || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
        return 0;
    }
    sf_params_t params;
    sf_params_default(&params);
    char err[512] = "";
    check(sf_config_load(path, &params, err, sizeof err), &params, err);

    char assignment[1024];
    size_t n = 0;
    while (n < size && n < sizeof assignment - 1 && data[n] != '\0' && data[n] != '\n') {
        assignment[n] = (char)data[n];
        n++;
    }
    assignment[n] = '\0';
    sf_params_default(&params);
    err[0] = '\0';
    check(sf_config_set(assignment, &params, err, sizeof err), &params, err);
    return 0;
}
