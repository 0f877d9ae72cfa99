/* sf_config_print.c — the parameter table as INI text and as JSON (see sf_config_print.h). */
#include "sf_config_print.h"

#include <math.h>
#include <string.h>

#include "sf_fusion.h"

#define INI_LINE_MAX 200 /* inih's INI_MAX_LINE: longer lines are split and misread */
#define WRAP_COLUMNS 110 /* wrapped comment lines stay within this */

_Static_assert(WRAP_COLUMNS < INI_LINE_MAX, "wrapped lines must fit inih's buffer");

/* Writes "# text" as is when it fits inih's line, else wrapped at spaces into "# " / "#   " lines. */
static void comment(FILE *const f, const char *const text)
{
    const size_t len = strlen(text);
    if (len + 3 <= INI_LINE_MAX) { /* "# ", the text, "\n" and fgets's NUL */
        fprintf(f, "# %s\n", text);
        return;
    }
    const char *p = text;
    const char *lead = "# ";
    while (*p != '\0') {
        const size_t room = WRAP_COLUMNS - strlen(lead);
        size_t n = strlen(p);
        if (n > room) {
            n = room;
            while (n > 0 && p[n] != ' ') {
                n--;
            }
            if (n == 0) {
                n = room; /* one word longer than a line: cut it */
            }
        }
        fprintf(f, "%s%.*s\n", lead, (int)n, p);
        p += n;
        while (*p == ' ') {
            p++;
        }
        lead = "#   ";
    }
}

void sf_config_print_ini(FILE *const f, const sf_params_t *const p)
{
    fprintf(f, "# stridefixd configuration keys (INI: [section] then key = value)\n");
    const char *section = "";
    for (size_t i = 0; i < sf_param_count; i++) {
        const sf_param_desc_t *const d = &sf_param_table[i];
        if (strcmp(section, d->section) != 0) {
            section = d->section;
            fprintf(f, "\n[%s]\n", section);
        }
        char text[512];
        snprintf(text, sizeof text, "%s [%s], range %g .. %g", d->text, d->unit, d->min_value, d->max_value);
        comment(f, text);
        fprintf(f, "%s = %.9g\n", d->name, sf_param_get(p, d));
    }
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void json_string(FILE *const f, const char *s)
{
    fputc('"', f);
    for (; *s != '\0'; s++) {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            fprintf(f, "\\%c", c);
        } else if (c < 0x20) {
            fprintf(f, "\\u%04x", (unsigned)c);
        } else {
            fputc(c, f);
        }
    }
    fputc('"', f);
}

/* A JSON number: integers as such, doubles exact (17 digits); a non-finite value as null. */
static void json_number(FILE *const f, const sf_param_kind_t kind, const double v)
{
    if (!isfinite(v)) {
        fputs("null", f);
    } else if (kind == sf_param_int32) {
        fprintf(f, "%.0f", v);
    } else {
        char text[32];
        snprintf(text, sizeof text, "%.17g", v);
        /* a double stays a JSON float ("0.0", not "0"), so readers keep the type */
        fprintf(f, "%s%s", text, strpbrk(text, ".e") == NULL ? ".0" : "");
    }
}

void sf_config_print_json(FILE *const f, const sf_params_t *const p)
{
    fputs("{\"params\": [", f);
    for (size_t i = 0; i < sf_param_count; i++) {
        const sf_param_desc_t *const d = &sf_param_table[i];
        char key[128];
        snprintf(key, sizeof key, "%s.%s", d->section, d->name);
        fputs(i > 0 ? ",\n  {\"key\": " : "\n  {\"key\": ", f);
        json_string(f, key);
        fputs(", \"section\": ", f);
        json_string(f, d->section);
        fputs(", \"name\": ", f);
        json_string(f, d->name);
        fprintf(f, ", \"type\": \"%s\", \"default\": ", d->kind == sf_param_int32 ? "int32" : "double");
        json_number(f, d->kind, d->default_value);
        fputs(", \"value\": ", f);
        json_number(f, d->kind, sf_param_get(p, d));
        fputs(", \"min\": ", f);
        json_number(f, d->kind, d->min_value);
        fputs(", \"max\": ", f);
        json_number(f, d->kind, d->max_value);
        fputs(", \"unit\": ", f);
        json_string(f, d->unit);
        fputs(", \"help\": ", f);
        json_string(f, d->text);
        fputc('}', f);
    }
    fputs("\n],\n\"schemes\": [", f);
    for (int s = 0; s < sf_scheme_count; s++) {
        fprintf(f, "%s{\"id\": %d, \"name\": ", s > 0 ? ", " : "", s);
        json_string(f, sf_fusion_scheme_name(s));
        fputc('}', f);
    }
    /* the controller's primary pose: not a fusion scheme, the id after the last one (pose_t.SCHEME_CONTROLLER) */
    fprintf(f, ", {\"id\": %d, \"name\": ", sf_scheme_controller);
    json_string(f, SF_SCHEME_CONTROLLER_NAME);
    fputs("}]}\n", f);
}
