/* sf_lcm_walk.c — bounds walk over an LCM encoding (see sf_lcm_walk.h). */
#include "sf_lcm_walk.h"

#include <stdarg.h>
#include <stdio.h>

#include "sf_error.h"

int sf_lcm_failf(char *const err, const size_t err_size, const char *const name, const int rc,
                 const char *const fmt, ...)
{
    if (err != NULL && err_size > 0) {
        char what[400];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(what, sizeof what, fmt, ap);
        va_end(ap);
        snprintf(err, err_size, "%s: %s", name, what);
    }
    return rc;
}

int32_t sf_lcm_be32(const uint8_t *const p)
{
    const uint32_t u = ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | (uint32_t)p[3];
    return (int32_t)u;
}

int sf_lcm_walk_skip(sf_lcm_walk_t *const w, const size_t bytes, const char *const field)
{
    if (bytes > w->size - w->pos) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX,
                            "payload ends inside field '%s' (needs %zu bytes at offset %zu, %zu left)", field,
                            bytes, w->pos, w->size - w->pos);
    }
    w->pos += bytes;
    return SF_OK;
}

int sf_lcm_walk_string(sf_lcm_walk_t *const w, const char *const field)
{
    int rc = sf_lcm_walk_skip(w, 4, field);
    if (rc != SF_OK) {
        return rc;
    }
    const int32_t len = sf_lcm_be32(w->p + w->pos - 4);
    if (len < 1) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX,
                            "payload: string '%s' has length %d, must be >= 1", field, (int)len);
    }
    rc = sf_lcm_walk_skip(w, (size_t)len, field);
    if (rc == SF_OK && w->p[w->pos - 1] != 0u) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX, "payload: string '%s' does not end with NUL",
                            field);
    }
    return rc;
}

int sf_lcm_walk_count(sf_lcm_walk_t *const w, const char *const field, const size_t element_bytes)
{
    int rc = sf_lcm_walk_skip(w, 4, field);
    if (rc != SF_OK) {
        return rc;
    }
    const int32_t n = sf_lcm_be32(w->p + w->pos - 4);
    if (n < 0) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX, "payload: %s = %d is negative", field, (int)n);
    }
    if ((size_t)n > (w->size - w->pos) / element_bytes) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX,
                            "payload: %s = %d needs %zu bytes of arrays, %zu left", field, (int)n,
                            (size_t)n * element_bytes, w->size - w->pos);
    }
    return sf_lcm_walk_skip(w, (size_t)n * element_bytes, field);
}

int sf_lcm_walk_end(const sf_lcm_walk_t *const w, const char *const type)
{
    if (w->pos != w->size) {
        return sf_lcm_failf(w->err, w->err_size, w->name, SF_ESYNTAX, "payload has %zu trailing bytes after the %s",
                            w->size - w->pos, type);
    }
    return SF_OK;
}
