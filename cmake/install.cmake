# cmake --install BUILD --prefix P: what a logger runs and what a user of the core library needs.
#   bin/stridefixd                              the daemon
#   lib/libsf_core.a, lib/libsf_lcmtypes.a       the estimator core, the LCM C bindings
#   lib/pkgconfig/stridefix-core.pc              cc $(pkg-config --cflags --libs stridefix-core)
#   include/stridefix/*.h                        the core's public headers (not *_internal.h), sf_schemes.h
#   include/stridefix/lcmtypes/*.h               the generated LCM C headers and sf_channels.h
#   share/stridefix/board.dbc                    the CAN frames the board sends
#   share/stridefix/lcmtypes/*.lcm, channels.csv the LCM type definitions and the channel table
#   share/stridefix/examples/                    stridefixd.ini (a logger's config), stridefixd-defaults.ini
#                                                (every key at its default: --print-config), stridefixd.default
#   lib/systemd/system/stridefixd.service        tools/systemd's unit, ExecStart at P/bin/stridefixd
#   share/man/man1/stridefixd.1                  from --help and --version (help2man, when installed)
#   SF_INSTALL_PYTHONDIR/stridefix/, stridefix_channels.py   the LCM Python types (P a venv: its site dir)
# Everything here is produced by the default build (a cross build has no man page nor defaults file: both
# run the built stridefixd); tests/python/packaging/test_install.py installs it.
include(GNUInstallDirs)

# The LCM Python types' site directory relative to the prefix: that of STRIDEFIX_PYTHON's default scheme
# (a venv: lib/pythonX.Y/site-packages, so `--prefix VENV` puts them where the venv imports from).
# Debian's system Python reports /usr/local/lib/... (its posix_local scheme) relative to /usr: "local/"
# is the prefix's own part, dropped.
execute_process(
  COMMAND ${STRIDEFIX_PYTHON} -c
    "import os, sysconfig; r = os.path.relpath(sysconfig.get_path('purelib'), sysconfig.get_config_var('base')); print(r[6:] if r.startswith('local/') else r)"
  OUTPUT_VARIABLE SF_PYTHON_SITE_REL OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE sf_py_rc)
if(NOT sf_py_rc EQUAL 0 OR SF_PYTHON_SITE_REL STREQUAL "")
  set(SF_PYTHON_SITE_REL lib/python3/dist-packages)
endif()
set(SF_INSTALL_PYTHONDIR "${SF_PYTHON_SITE_REL}" CACHE STRING
    "where cmake --install puts the LCM Python types, relative to the prefix (or absolute)")

install(TARGETS stridefixd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS sf_core sf_lcmtypes ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})

file(GLOB sf_core_headers CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/firmware/core/sf_*.h)
list(FILTER sf_core_headers EXCLUDE REGEX "_internal\\.h$")
install(FILES ${sf_core_headers} ${CMAKE_BINARY_DIR}/gen/schemes/sf_schemes.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/stridefix)
install(DIRECTORY ${CMAKE_BINARY_DIR}/lcmtypes/c/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/stridefix/lcmtypes
        FILES_MATCHING PATTERN "*.h")
string(REGEX REPLACE "[^/]+" ".." SF_PC_UP "${CMAKE_INSTALL_LIBDIR}/pkgconfig") # lib/pkgconfig -> ../..
configure_file(${CMAKE_SOURCE_DIR}/cmake/stridefix-core.pc.in ${CMAKE_BINARY_DIR}/stridefix-core.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/stridefix-core.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

install(FILES ${CMAKE_SOURCE_DIR}/firmware/board.dbc DESTINATION ${CMAKE_INSTALL_DATADIR}/stridefix)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/lcmtypes/stridefix/ DESTINATION ${CMAKE_INSTALL_DATADIR}/stridefix/lcmtypes
        FILES_MATCHING PATTERN "*.lcm")
install(FILES ${CMAKE_SOURCE_DIR}/lcmtypes/channels.csv DESTINATION ${CMAKE_INSTALL_DATADIR}/stridefix/lcmtypes)
install(DIRECTORY ${CMAKE_BINARY_DIR}/lcmtypes/python/stridefix DESTINATION ${SF_INSTALL_PYTHONDIR}
        FILES_MATCHING PATTERN "*.py")
install(FILES ${CMAKE_BINARY_DIR}/lcmtypes/python/stridefix_channels.py DESTINATION ${SF_INSTALL_PYTHONDIR})

install(FILES ${CMAKE_SOURCE_DIR}/firmware/examples/stridefixd.ini ${CMAKE_SOURCE_DIR}/firmware/examples/stridefixd.default
        DESTINATION ${CMAKE_INSTALL_DATADIR}/stridefix/examples)

# The unit names the binary by its installed path: tools/systemd's says /usr/local/bin, rewritten at
# install time (the prefix of `cmake --install --prefix P` is only known then).
install(CODE "
  file(READ \"${CMAKE_SOURCE_DIR}/tools/systemd/stridefixd.service\" unit)
  string(REPLACE \"/usr/local/bin/stridefixd\" \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}/stridefixd\" unit \"\${unit}\")
  set(dir \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/lib/systemd/system\")
  message(STATUS \"Installing: \${dir}/stridefixd.service\")
  file(MAKE_DIRECTORY \"\${dir}\")
  file(WRITE \"\${dir}/stridefixd.service\" \"\${unit}\")
")

# Both generated files run the built stridefixd: not when cross-compiling; under check-asan/check-fuzz
# without LeakSanitizer (what --help leaves allocated at exit is no finding of this build step).
if(CMAKE_CROSSCOMPILING)
  return()
endif()
set(SF_RUN_BUILT ${CMAKE_COMMAND} -E env ASAN_OPTIONS=detect_leaks=0)

# Every key at its default, from the binary itself: it cannot drift from the parameter table.
set(SF_DEFAULTS_INI ${CMAKE_BINARY_DIR}/firmware/stridefixd-defaults.ini)
add_custom_command(
  OUTPUT ${SF_DEFAULTS_INI}
  COMMAND ${SF_RUN_BUILT} ${CMAKE_COMMAND} -DOUT=${SF_DEFAULTS_INI} -DEXE=$<TARGET_FILE:stridefixd> -DARG=--print-config
          -P ${CMAKE_SOURCE_DIR}/cmake/run_to_file.cmake
  DEPENDS stridefixd ${CMAKE_SOURCE_DIR}/cmake/run_to_file.cmake
  COMMENT "stridefixd --print-config > stridefixd-defaults.ini")
set(sf_install_generated ${SF_DEFAULTS_INI})
install(FILES ${SF_DEFAULTS_INI} DESTINATION ${CMAKE_INSTALL_DATADIR}/stridefix/examples)

# The man page from --help and --version (help2man: Debian package help2man, make deps installs it).
find_program(HELP2MAN help2man)
set(SF_MAN_PAGE ${CMAKE_BINARY_DIR}/firmware/stridefixd.1)
if(HELP2MAN)
  add_custom_command(
    OUTPUT ${SF_MAN_PAGE}
    COMMAND ${SF_RUN_BUILT} ${HELP2MAN} --no-info --section=1 --include=${CMAKE_SOURCE_DIR}/tools/man/stridefixd.h2m
            --name=logger\ of\ the\ StrideFix\ board:\ CAN\ frames\ to\ estimator\ to\ LCM\ log
            --output=${SF_MAN_PAGE} $<TARGET_FILE:stridefixd>
    DEPENDS stridefixd ${CMAKE_SOURCE_DIR}/tools/man/stridefixd.h2m
    COMMENT "help2man: stridefixd.1")
  list(APPEND sf_install_generated ${SF_MAN_PAGE})
  install(FILES ${SF_MAN_PAGE} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "help2man not found: no man page (make deps installs it)")
endif()
add_custom_target(sf_install_files ALL DEPENDS ${sf_install_generated})
