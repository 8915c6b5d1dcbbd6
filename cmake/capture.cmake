# cmake -DEXE=program -DARG=argument -DOUT=file -P capture.cmake: runs `program argument` and
# writes its standard output to file, failing the build if the program fails.
get_filename_component(dir ${OUT} DIRECTORY)
file(MAKE_DIRECTORY ${dir})
execute_process(COMMAND ${EXE} ${ARG} OUTPUT_FILE ${OUT}.tmp RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE ${OUT}.tmp)
  message(FATAL_ERROR "${EXE} ${ARG} failed (${rc})")
endif()
file(RENAME ${OUT}.tmp ${OUT})
