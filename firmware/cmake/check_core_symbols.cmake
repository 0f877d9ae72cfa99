# The core's "no heap, no I/O, no clock" rule checked on the object code (a source review misses a
# call a macro or a library hides): every symbol the core library needs from outside itself (nm -u)
# is an sf_* function of the core, or on the allowlist
# below (libm, the mem*/str* functions that never allocate, compiler runtime helpers). A heap call
# hidden in libc (qsort may malloc), printf, a file or a clock fails the build's tests.
#   cmake -DNM=<nm> -DLIB=<libsf_core.a> -P check_core_symbols.cmake
set(SF_CORE_ALLOWED
  # libm
  acos asin atan atan2 cbrt ceil cos cosh exp exp2 expm1 fabs floor fma fmax fmin fmod hypot ldexp log
  log10 log1p log2 lrint lround modf nearbyint pow remainder rint round sin sincos sinh sqrt tan tanh
  trunc acosf asinf atan2f cosf expf fabsf floorf fmaxf fminf hypotf logf powf roundf sinf sqrtf tanf
  # string.h functions that never allocate
  memchr memcmp memcpy memmove memset strcmp strlen strncmp
  # compiler and ABI runtime (64-bit integer division on 32-bit ARM, stack protector, PIC)
  _GLOBAL_OFFSET_TABLE_ __stack_chk_fail __stack_chk_guard)
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "check_core_symbols: ${NM} -u ${LIB} failed (${rc})")
endif()
string(REPLACE "\n" ";" lines "${out}")
set(bad "")
set(n 0)
foreach(line ${lines})
  string(STRIP "${line}" line)
  if(line MATCHES "^U +([^ ]+)$")
    set(sym "${CMAKE_MATCH_1}")
    string(REGEX REPLACE "@.*$" "" sym "${sym}")
    math(EXPR n "${n} + 1")
    if(sym MATCHES "^sf_" OR sym MATCHES "^__aeabi_" OR sym MATCHES "^__(u)?(div|mod)[dt]i3$")
      continue()
    endif()
    list(FIND SF_CORE_ALLOWED "${sym}" at)
    if(at EQUAL -1)
      list(APPEND bad "${sym}")
    endif()
  endif()
endforeach()
if(n EQUAL 0)
  message(FATAL_ERROR "check_core_symbols: no undefined symbol read from ${LIB}: is it the core library?")
endif()
if(bad)
  list(REMOVE_DUPLICATES bad)
  message(FATAL_ERROR "check_core_symbols: firmware/core calls what its rules forbid (heap, I/O, clock "
                      "or an unlisted libc function): ${bad}")
endif()
message(STATUS "check_core_symbols: ${n} undefined references, all sf_*, libm, mem*/str* or runtime")
