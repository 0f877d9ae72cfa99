/* sf_config.c — INI config via inih, checked against the parameter table (see sf_config.h). */
#include "sf_config.h"

#include <errno.h>
#include <stdbool.h>
#include <ini.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_file_kind.h"

#define KEY_MAX 128 /* "section.name" of --set; longer than every key of SF_PARAM_LIST */

typedef struct {
    sf_params_t *params;
    int rc;
    char what[200];
    FILE *f;
    int line_no;  /* lines handed to inih so far */
    int bad_line; /* the line the reader refused (too long for inih, or a NUL byte), or 0 */
    char bad_what[80];
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

/* inih's line reader (fgets's contract, num = the library's INI_MAX_LINE, whatever it was built
 * with): one whole line, or NULL to stop. A line that does not fit, or holds a NUL byte, is refused
 * here with its number: inih would split it and report a later line, or silently cut it. */
static char *read_line(char *const str, const int num, void *const stream)
{
    ctx_t *const ctx = stream;
    if (ctx->rc != SF_OK || ctx->bad_line != 0) {
        return NULL; /* after the first error nothing more is read */
    }
    int n = 0;
    int c = EOF;
    while (n < num - 1 && (c = getc(ctx->f)) != EOF) {
        if (c == '\0') {
            ctx->bad_line = ctx->line_no + 1;
            snprintf(ctx->bad_what, sizeof ctx->bad_what, "a NUL byte: not a text file");
            return NULL;
        }
        str[n++] = (char)c;
        if (c == '\n') {
            break;
        }
    }
    if (n == 0) {
        return NULL; /* end of file */
    }
    if (str[n - 1] != '\n' && (c = getc(ctx->f)) != EOF && c != '\n') {
        ctx->bad_line = ctx->line_no + 1;
        snprintf(ctx->bad_what, sizeof ctx->bad_what, "line longer than the %d characters a config line may have",
                 num - 1);
        return NULL;
    }
    str[n] = '\0';
    ctx->line_no++;
    return str;
}

int sf_config_load(const char *const path, sf_params_t *const params, char *const err, const size_t err_size)
{
    const int kind_rc = sf_file_check(path, "config", true, err, err_size);
    if (kind_rc != SF_OK) {
        return kind_rc;
    }
    FILE *const f = fopen(path, "r");
    if (f == NULL) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open config: %s", path, strerror(e));
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    ctx_t ctx = {.params = params, .rc = SF_OK, .f = f};
    int line = ini_parse_stream(read_line, &ctx, on_entry, &ctx);
    const bool read_failed = ferror(f) != 0;
    fclose(f);
    if (read_failed && ctx.rc == SF_OK && ctx.bad_line == 0) {
        snprintf(err, err_size, "%s: cannot read config", path);
        return SF_EIO;
    }
    if (ctx.bad_line != 0 && (line == 0 || line > ctx.bad_line)) {
        line = ctx.bad_line;
        ctx.rc = SF_ESYNTAX;
        snprintf(ctx.what, sizeof ctx.what, "%s", ctx.bad_what);
    }
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
    /* Only the key is copied (bounded: no key is that long); the value is read in place, so no
     * argument is ever cut short. */
    const char *const eq = strchr(assignment, '=');
    const char *const dot = strchr(assignment, '.');
    if (dot == NULL || eq == NULL || dot > eq) {
        snprintf(err, err_size, "--set %.200s: expected section.name=value", assignment);
        return SF_ESYNTAX;
    }
    const size_t key_len = (size_t)(eq - assignment);
    if (key_len >= KEY_MAX) {
        snprintf(err, err_size, "--set: the key '%.40s...' (%zu characters) is not a key (see --print-config)",
                 assignment, key_len);
        return SF_ESYNTAX;
    }
    char buf[KEY_MAX];
    memcpy(buf, assignment, key_len);
    buf[key_len] = '\0';
    buf[dot - assignment] = '\0';
    char what[200];
    const int rc = apply(params, buf, buf + (dot - assignment) + 1, eq + 1, what, sizeof what);
    if (rc != SF_OK) {
        snprintf(err, err_size, "--set: %s", what);
    }
    return rc;
}
