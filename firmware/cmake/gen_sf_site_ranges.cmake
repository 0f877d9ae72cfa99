# Generates sf_site_ranges_table.h from firmware/site_ranges.tsv (the site fields' physical ranges, the one
# table both site readers check), so the C loader never re-types a limit (run at build time:
# cmake -DIN=site_ranges.tsv -DOUT=sf_site_ranges_table.h -P). Each row becomes one X-macro entry, in the
# table's order:
#   SCALAR(field, when, lo, hi, unit)                     a scalar field
#   ARRAY(field, count, label, when, lo, hi, unit, nan)   count: s->n_* or a number; label NULL: field[i]
# `when` and `count` are expressions on `s` (the const stridefix_site_t * in scope where it expands).
# Each count row (a field n_*) also gives SF_SITE_RANGE_MAX_<field>, its largest value.
cmake_policy(SET CMP0054 NEW)
file(STRINGS ${IN} lines ENCODING UTF-8)
set(rows "")
set(count_limits "")
set(header_seen FALSE)
foreach(line IN LISTS lines)
  if(line MATCHES "^#" OR line MATCHES "^[ \t]*$")
    continue()
  endif()
  string(REPLACE "\t" ";" cells "${line}")
  list(LENGTH cells n)
  if(NOT n EQUAL 8)
    message(FATAL_ERROR "${IN}: ${n} columns in '${line}', expected 8")
  endif()
  if(NOT header_seen)
    if(NOT line STREQUAL "field\tcount\tlabel\twhen\tmin\tmax\tunit\tnan")
      message(FATAL_ERROR "${IN}: header '${line}' is not field count label when min max unit nan")
    endif()
    set(header_seen TRUE)
    continue()
  endif()
  list(GET cells 0 field)
  list(GET cells 1 count)
  list(GET cells 2 label)
  list(GET cells 3 when)
  list(GET cells 4 lo)
  list(GET cells 5 hi)
  list(GET cells 6 unit)
  list(GET cells 7 nan_ok)
  foreach(v lo hi)
    if(NOT "${${v}}" MATCHES "^-?[0-9]+(\\.[0-9]+)?$")
      message(FATAL_ERROR "${IN}: ${field}: ${v} '${${v}}' is not a number")
    endif()
  endforeach()
  if(when STREQUAL "-")
    set(when "1")
  else()
    set(when "(s->${when} != 0)")
  endif()
  if(unit STREQUAL "-")
    set(unit "\"\"")
  else()
    set(unit "\" ${unit}\"")
  endif()
  if(field MATCHES "^n_")
    string(APPEND count_limits "#define SF_SITE_RANGE_MAX_${field} ${hi}\n")
  endif()
  if(count STREQUAL "-")
    string(APPEND rows "    SCALAR(${field}, ${when}, ${lo}.0, ${hi}.0, ${unit}) \\\n")
  else()
    if(NOT count MATCHES "^[0-9]+$")
      set(count "s->${count}")
    endif()
    if(label STREQUAL "-")
      set(label "NULL")
    else()
      set(label "\"${label}\"")
    endif()
    if(nan_ok STREQUAL "nan")
      set(nan_ok 1)
    else()
      set(nan_ok 0)
    endif()
    string(APPEND rows "    ARRAY(${field}, ${count}, ${label}, ${when}, ${lo}.0, ${hi}.0, ${unit}, ${nan_ok}) \\\n")
  endif()
endforeach()
set(header "/* sf_site_ranges_table.h — GENERATED at build time from firmware/site_ranges.tsv by
 * firmware/cmake/gen_sf_site_ranges.cmake; never edit or commit it. The site fields' physical ranges,
 * in the table's order, for sf_site_ranges.c (see gen_sf_site_ranges.cmake for the two entry kinds). */
#ifndef SF_SITE_RANGES_TABLE_H
#define SF_SITE_RANGES_TABLE_H

#define SF_SITE_RANGES(SCALAR, ARRAY) \\
${rows}
/* the largest count of each count row (the firmware's capacities, asserted in sf_site_ranges.c) */
${count_limits}
#endif
")
set(tmp "${OUT}.tmp")
file(WRITE "${tmp}" "${header}")
configure_file("${tmp}" "${OUT}" COPYONLY)
file(REMOVE "${tmp}")
