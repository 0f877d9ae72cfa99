# Generates sf_channels.h and stridefix_channels.py from lcmtypes/channels.csv, so neither C nor Python
# re-types a channel name or its type (run at build time:
#   cmake -DIN=channels.csv -DOUT_H=sf_channels.h -DOUT_PY=stridefix_channels.py -P gen_channels.cmake).
# Each type must exist as lcmtypes/stridefix/<type>.lcm.
file(STRINGS ${IN} lines)
get_filename_component(dir ${IN} DIRECTORY)
set(c_rows "")
set(c_defs "")
set(py_rows "")
foreach(line ${lines})
  if(line MATCHES "^#" OR line STREQUAL "")
    continue()
  endif()
  if(NOT line MATCHES "^([A-Z][A-Z0-9_]*),([a-z][a-z0-9_]*_t),(.+)$")
    message(FATAL_ERROR "${IN}: not 'CHANNEL,type_t,written by': ${line}")
  endif()
  set(name ${CMAKE_MATCH_1})
  set(type ${CMAKE_MATCH_2})
  set(writer ${CMAKE_MATCH_3})
  if(NOT EXISTS ${dir}/stridefix/${type}.lcm)
    message(FATAL_ERROR "${IN}: channel ${name}: no lcmtypes/stridefix/${type}.lcm")
  endif()
  string(APPEND c_defs "#define SF_CHANNEL_${name} \"${name}\"\n")
  string(APPEND c_rows "    X(${name}, stridefix_${type}) \\\n")
  string(APPEND py_rows "    (\"${name}\", \"${type}\", \"${writer}\"),\n")
endforeach()
set(header "/* sf_channels.h — GENERATED at build time from lcmtypes/channels.csv by lcmtypes/gen_channels.cmake;
 * never edit or commit it. SF_CHANNEL_<NAME> is the channel's name; X(NAME, generated C type). */
#ifndef SF_CHANNELS_H
#define SF_CHANNELS_H

${c_defs}
#define SF_CHANNELS(X) \\
${c_rows}
#endif
")
set(py "\"\"\"GENERATED at build time from lcmtypes/channels.csv by lcmtypes/gen_channels.cmake; never edit.

CHANNELS: (channel, LCM type name in package stridefix, written by), in the file's order.
\"\"\"

CHANNELS = (
${py_rows})
")
foreach(pair "OUT_H;header" "OUT_PY;py")
  list(GET pair 0 var)
  list(GET pair 1 content)
  # rewrite only on change, so an unrelated edit rebuilds nothing
  file(WRITE "${${var}}.tmp" "${${content}}")
  configure_file("${${var}}.tmp" "${${var}}" COPYONLY)
  file(REMOVE "${${var}}.tmp")
endforeach()
