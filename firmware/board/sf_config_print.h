/* sf_config_print.h — the parameter table (SF_PARAM_LIST, firmware/core/sf_params.h) written out:
 * as INI text that sf_config_load reads back (`stridefixd --print-config`), and as JSON for tools
 * (`--print-config --json`), so the analyzer reads keys, defaults and ranges instead of re-typing them.
 *
 * INI: a `# meaning [unit], range min .. max` comment and `name = value` per key under its
 * `[section]`; comments longer than inih's line limit (INI_MAX_LINE, 200) are wrapped, so the output
 * is always a valid config (print, edit, --config).
 * JSON: {"params": [{"key", "section", "name", "type" ("double" | "int32"), "default", "value" (the
 * effective one), "min", "max", "unit", "help"}, ...], "schemes": [{"id", "name"}, ...]} with
 * doubles at 17 significant digits (exact) and the schemes of pose_t.SCHEME_*.
 * Cannot fail (write errors show in ferror(f)). */
#ifndef SF_CONFIG_PRINT_H
#define SF_CONFIG_PRINT_H

#include <stdio.h>

#include "sf_params.h"

void sf_config_print_ini(FILE *f, const sf_params_t *params);
void sf_config_print_json(FILE *f, const sf_params_t *params);

#endif
