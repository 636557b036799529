# Configures and generates kincal (SOURCE_DIR) with every combination of KINCAL_BUILD_TESTS,
# KINCAL_BUILD_TOOLS and KINCAL_BUILD_PYTHON, and with no build type (ctest: cmake_option_combinations).
file(REMOVE_RECURSE ${WORK_DIR})
set(i 0)
foreach(tests ON OFF)
  foreach(tools ON OFF)
    foreach(python ON OFF)
      math(EXPR i "${i} + 1")
      set(dir ${WORK_DIR}/${i})
      execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${dir} -G ${GENERATOR}
        -DKINCAL_BUILD_TESTS=${tests} -DKINCAL_BUILD_TOOLS=${tools} -DKINCAL_BUILD_PYTHON=${python}
        "-DCMAKE_PREFIX_PATH=${PREFIX_PATH}"
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "tests=${tests} tools=${tools} python=${python}: configure failed\n${out}\n${err}")
      endif()
      message(STATUS "tests=${tests} tools=${tools} python=${python}: configured and generated")
    endforeach()
  endforeach()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
