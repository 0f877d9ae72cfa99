# cmake -DEXE=PROGRAM -DARG=ARGUMENT -DOUT=FILE -P run_to_file.cmake: PROGRAM ARGUMENT's stdout into FILE;
# fails when PROGRAM does (a custom command's shell redirection is not portable across CMake generators).
execute_process(COMMAND ${EXE} ${ARG} OUTPUT_FILE ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE ${OUT})
  message(FATAL_ERROR "${EXE} ${ARG}: exit ${rc}")
endif()
