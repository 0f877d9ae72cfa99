# Generates sf_schemes.h from the SCHEME_* constants of lcmtypes/stridefix/pose_t.lcm, so the C side
# never re-types the scheme ids and names (run at build time: cmake -DIN=pose_t.lcm -DOUT=sf_schemes.h -P).
# The ids must be 0, 1, 2, ... in order: the core indexes its per-scheme arrays by them.
# SCHEME_CONTROLLER is not a fusion scheme (it follows one: firmware/core/sf_controller.h): it is left
# out of SF_SCHEMES and given as SF_SCHEME_CONTROLLER, and must be the last id.
file(READ ${IN} text)
string(REGEX MATCH "SCHEME_CONTROLLER[ \t\r\n]*=[ \t\r\n]*([0-9]+)" controller "${text}")
if(NOT controller)
  message(FATAL_ERROR "${IN}: no SCHEME_CONTROLLER constant")
endif()
set(controller_id ${CMAKE_MATCH_1})
string(REGEX REPLACE "SCHEME_CONTROLLER[ \t\r\n]*=[ \t\r\n]*[0-9]+" "" text "${text}")
string(REGEX MATCHALL "SCHEME_[A-Z0-9_]+[ \t\r\n]*=[ \t\r\n]*[0-9]+" pairs "${text}")
if(NOT pairs)
  message(FATAL_ERROR "${IN}: no SCHEME_* constants")
endif()
set(rows "")
set(expected 0)
foreach(pair ${pairs})
  string(REGEX REPLACE "^SCHEME_([A-Z0-9_]+).*$" "\\1" upper "${pair}")
  string(REGEX REPLACE "^.*=[ \t\r\n]*([0-9]+)$" "\\1" id "${pair}")
  if(NOT id EQUAL expected)
    message(FATAL_ERROR "${IN}: SCHEME_${upper} = ${id}, expected ${expected} (ids must be 0, 1, 2, ... in order)")
  endif()
  string(TOLOWER "${upper}" lower)
  string(APPEND rows "    X(${lower}, ${id}) \\\n")
  math(EXPR expected "${expected} + 1")
endforeach()
if(NOT controller_id EQUAL expected)
  message(FATAL_ERROR "${IN}: SCHEME_CONTROLLER = ${controller_id}, expected ${expected} (the last id)")
endif()
set(header "/* sf_schemes.h — GENERATED at build time from lcmtypes/stridefix/pose_t.lcm (SCHEME_*) by
 * firmware/cmake/gen_sf_schemes.cmake; never edit or commit it. X(name, id): the lower-case scheme
 * name (a C token; #name is its spelling in --fusion and the JSON config) and its pose_t.SCHEME_* id. */
#ifndef SF_SCHEMES_H
#define SF_SCHEMES_H

#define SF_SCHEMES(X) \\
${rows}
#define SF_SCHEME_COUNT ${expected}
/* the multi-scheme controller's primary pose: not a fusion scheme, the id after the last one */
#define SF_SCHEME_CONTROLLER ${controller_id}
#define SF_SCHEME_CONTROLLER_NAME \"controller\"

#endif
")
# Rewrite only on change, so an unrelated edit of pose_t.lcm rebuilds nothing.
set(tmp "${OUT}.tmp")
file(WRITE "${tmp}" "${header}")
configure_file("${tmp}" "${OUT}" COPYONLY)
file(REMOVE "${tmp}")
