/* sf_config.c — INI config via inih, checked against the parameter table (see sf_config.h). */
#include "sf_config.h"

#include <errno.h>
#include <ini.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"

typedef struct {
    sf_params_t *params;
    int rc;
    char what[200];
} ctx_t;

/* Parses and applies one value; rc and a message on failure. */
static int apply(sf_params_t *const params, const char *const section, const char *const name,
                 const char *const value, char *const what, const size_t what_size)
{
    const sf_param_desc_t *const d = sf_param_find(section, name);
    if (d == NULL) {
        snprintf(what, what_size, "unknown key '%s' in section [%s]", name, section);
        return SF_ESYNTAX;
    }
    char *end = NULL;
    errno = 0;
    const double v = strtod(value, &end);
    if (end == value || *end != '\0' || errno != 0) {
        snprintf(what, what_size, "%s.%s: '%s' is not a number", section, name, value);
        return SF_ESYNTAX;
    }
    const int rc = sf_param_set(params, d, v);
    if (rc != SF_OK) {
        snprintf(what, what_size, "%s.%s = %s: must be %s in [%g, %g] %s", section, name, value,
                 d->kind == sf_param_int32 ? "an integer" : "a number", d->min_value, d->max_value, d->unit);
        return SF_ERANGE;
    }
    return SF_OK;
}

static int on_entry(void *const user, const char *const section, const char *const name, const char *const value)
{
    ctx_t *const ctx = user;
    if (ctx->rc != SF_OK) {
        return 0; /* inih goes on after an error: keep the first one, apply nothing after it */
    }
    ctx->rc = apply(ctx->params, section, name, value, ctx->what, sizeof ctx->what);
    return ctx->rc == SF_OK;
}

int sf_config_load(const char *const path, sf_params_t *const params, char *const err, const size_t err_size)
{
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open config: %s", path, strerror(e));
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    ctx_t ctx = {params, SF_OK, ""};
    const int line = ini_parse_file(f, on_entry, &ctx);
    fclose(f);
    if (line == 0) {
        return SF_OK;
    }
    if (ctx.rc == SF_OK) {
        snprintf(ctx.what, sizeof ctx.what, "not 'key = value' or '[section]'");
        ctx.rc = SF_ESYNTAX;
    }
    snprintf(err, err_size, "%s:%d: %s", path, line, ctx.what);
    return ctx.rc;
}

int sf_config_set(const char *const assignment, sf_params_t *const params, char *const err, const size_t err_size)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", assignment);
    char *const dot = strchr(buf, '.');
    char *const eq = strchr(buf, '=');
    if (dot == NULL || eq == NULL || dot > eq) {
        snprintf(err, err_size, "--set %s: expected section.name=value", assignment);
        return SF_ESYNTAX;
    }
    *dot = '\0';
    *eq = '\0';
    char what[200];
    const int rc = apply(params, buf, dot + 1, eq + 1, what, sizeof what);
    if (rc != SF_OK) {
        snprintf(err, err_size, "--set: %s", what);
    }
    return rc;
}
