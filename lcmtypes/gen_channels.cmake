# Generates sf_channels.h and stridefix_channels.py from lcmtypes/channels.csv, so neither C nor Python
# re-types a channel name or its type (run at build time:
#   cmake -DIN=channels.csv -DOUT_H=sf_channels.h -DOUT_PY=stridefix_channels.py -P gen_channels.cmake).
# Each type must exist as lcmtypes/stridefix/<type>.lcm. A row whose name holds <SCHEME> stands for one
# channel per fusion scheme of pose_t.lcm (SCHEME_* but SCHEME_CONTROLLER, id order), the names never
# retyped: POSE_<SCHEME> gives POSE_PDR_ONLY ... POSE_PARTICLE, and SF_CHANNEL_POSE_OF_SCHEME /
# POSE_SCHEME_CHANNELS map a scheme id to its channel.
include(${CMAKE_CURRENT_LIST_DIR}/read_schemes.cmake)
file(STRINGS ${IN} lines)
get_filename_component(dir ${IN} DIRECTORY)
sf_read_schemes(${dir}/stridefix/pose_t.lcm schemes controller_id)
set(c_rows "")
set(c_defs "")
set(py_rows "")
set(scheme_c "")
set(scheme_py "")
foreach(line ${lines})
  if(line MATCHES "^#" OR line STREQUAL "")
    continue()
  endif()
  if(NOT line MATCHES "^([A-Z][A-Z0-9_]*(<SCHEME>)?),([a-z][a-z0-9_]*_t),(.+)$")
    message(FATAL_ERROR "${IN}: not 'CHANNEL,type_t,written by': ${line}")
  endif()
  set(pattern ${CMAKE_MATCH_1})
  set(type ${CMAKE_MATCH_3})
  set(writer ${CMAKE_MATCH_4})
  if(NOT EXISTS ${dir}/stridefix/${type}.lcm)
    message(FATAL_ERROR "${IN}: channel ${pattern}: no lcmtypes/stridefix/${type}.lcm")
  endif()
  set(names ${pattern})
  if(pattern MATCHES "<SCHEME>")
    if(NOT scheme_c STREQUAL "")
      message(FATAL_ERROR "${IN}: more than one per-scheme channel row: ${line}")
    endif()
    set(names "")
    set(id 0)
    foreach(upper ${schemes})
      string(REPLACE "<SCHEME>" "${upper}" name "${pattern}")
      list(APPEND names ${name})
      string(APPEND scheme_c "    X(${name}, ${id}) \\\n")
      string(APPEND scheme_py "    ${id}: \"${name}\",\n")
      math(EXPR id "${id} + 1")
    endforeach()
  endif()
  foreach(name ${names})
    string(APPEND c_defs "#define SF_CHANNEL_${name} \"${name}\"\n")
    string(APPEND c_rows "    X(${name}, stridefix_${type}) \\\n")
    string(APPEND py_rows "    (\"${name}\", \"${type}\", \"${writer}\"),\n")
  endforeach()
endforeach()
set(header "/* sf_channels.h — GENERATED at build time from lcmtypes/channels.csv by lcmtypes/gen_channels.cmake;
 * never edit or commit it. SF_CHANNEL_<NAME> is the channel's name; X(NAME, generated C type).
 * SF_CHANNEL_POSE_SCHEMES: X(NAME, pose_t.SCHEME_* id), one per-scheme channel per fusion scheme. */
#ifndef SF_CHANNELS_H
#define SF_CHANNELS_H

${c_defs}
#define SF_CHANNELS(X) \\
${c_rows}
#define SF_CHANNEL_POSE_SCHEMES(X) \\
${scheme_c}
#endif
")
set(py "\"\"\"GENERATED at build time from lcmtypes/channels.csv by lcmtypes/gen_channels.cmake; never edit.

CHANNELS: (channel, LCM type name in package stridefix, written by), in the file's order.
POSE_SCHEME_CHANNELS: pose_t.SCHEME_* id of each fusion scheme -> the channel of its own poses.
\"\"\"

CHANNELS = (
${py_rows})

POSE_SCHEME_CHANNELS = {
${scheme_py}}
")
foreach(pair "OUT_H;header" "OUT_PY;py")
  list(GET pair 0 var)
  list(GET pair 1 content)
  # rewrite only on change, so an unrelated edit rebuilds nothing
  file(WRITE "${${var}}.tmp" "${${content}}")
  configure_file("${${var}}.tmp" "${${var}}" COPYONLY)
  file(REMOVE "${${var}}.tmp")
endforeach()
