# Generates sf_schemes.h from the SCHEME_* constants of lcmtypes/stridefix/pose_t.lcm, so the C side
# never re-types the scheme ids and names (run at build time: cmake -DIN=pose_t.lcm -DOUT=sf_schemes.h -P).
# The ids must be 0, 1, 2, ... in order: the core indexes its per-scheme arrays by them.
# SCHEME_CONTROLLER is not a fusion scheme (it follows one: firmware/core/sf_controller.h): it is left
# out of SF_SCHEMES and given as SF_SCHEME_CONTROLLER, and must be the last id.
include(${CMAKE_CURRENT_LIST_DIR}/../../lcmtypes/read_schemes.cmake)
sf_read_schemes(${IN} schemes controller_id)
set(rows "")
set(expected 0)
foreach(upper ${schemes})
  string(TOLOWER "${upper}" lower)
  string(APPEND rows "    X(${lower}, ${expected}) \\\n")
  math(EXPR expected "${expected} + 1")
endforeach()
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
