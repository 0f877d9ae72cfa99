#!/usr/bin/env bash
# make check-arm: the estimator core's size on the unit's ARM processor, the totals of `size -t` over
# the objects of libsf_core.a, written as JSON; exit 1 when text is over its budget.
# Berkeley figures: text = code + read-only data (strings, tables), data = initialised writable data
# (in this PIE build the core's const pointer tables, .data.rel.ro), bss = zero-initialised data.
#   tools/core_size.sh SIZE_TOOL LIB OUT_JSON BUDGET_TEXT_B
set -euo pipefail
if [ $# -ne 4 ]; then
  echo "usage: $0 SIZE_TOOL LIB OUT_JSON BUDGET_TEXT_B" >&2
  exit 2
fi
size_tool=$1 lib=$2 out=$3 budget=$4
if [ ! -f "$lib" ]; then
  echo "core_size: $lib not found: build the core first" >&2
  exit 1
fi
read -r text data bss < <("$size_tool" -t "$lib" | awk '/\(TOTALS\)/ {print $1, $2, $3}') || true
if [ -z "${bss:-}" ]; then
  echo "core_size: no (TOTALS) line in the output of $size_tool -t $lib" >&2
  exit 1
fi
met=true
[ "$text" -le "$budget" ] || met=false
printf '{"lib": "%s", "text_B": %d, "data_B": %d, "bss_B": %d, "budget_text_B": %d, "met": %s}\n' \
  "$lib" "$text" "$data" "$bss" "$budget" "$met" > "$out"
echo "core size (ARM): text $text B ($(((text * 100 + budget / 2) / budget)) % of the $budget B budget), data $data B, bss $bss B -> $out"
if [ "$met" != true ]; then
  echo "core_size: FAILED: the core's text is $text B, over its budget of $budget B" >&2
  exit 1
fi
