# SF_CORE_ONLY (make check-arm): the core tests as the unit's processor runs them, cross-compiled and
# run under qemu. Each links the core alone, so a core test that grows a board dependency fails here.
set(SF_C_ARM_TESTS ${SF_C_CORE_TESTS})
foreach(t ${SF_C_ARM_TESTS})
  add_executable(test_${t} test_${t}.c)
  target_include_directories(test_${t} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR} ${CMOCKA_INCLUDE_DIR})
  target_compile_options(test_${t} PRIVATE ${SF_WARNINGS} ${SF_WARNINGS_STRICT})
  target_link_libraries(test_${t} PRIVATE sf_core ${CMOCKA_LIBRARY} m)
  add_test(NAME ${t} COMMAND test_${t})
endforeach()
# qemu runs slower than the host: more time than the host build's 30 s. The pre-selection's test
# (5 s native) took 64 s under qemu on an idle machine and over 120 s in a loaded CI run: 600 s.
set_tests_properties(${SF_C_ARM_TESTS} PROPERTIES TIMEOUT 120)
set_tests_properties(fingerprint_preselect PROPERTIES TIMEOUT 600)
