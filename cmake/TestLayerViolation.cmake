# Configures the project with one injected layer violation (-DVIOLATION=…) and succeeds only if
# configuration fails with the architecture message. Run as:
#   cmake -DROOT=<repo> -DWORK=<scratch dir> -DVIOLATION=calfit_links_sim -P TestLayerViolation.cmake
file(REMOVE_RECURSE "${WORK}")
execute_process(
  COMMAND ${CMAKE_COMMAND} -S "${ROOT}" -B "${WORK}" -G Ninja -DFTSTACK_BUILD_TESTS=OFF
          -DFTSTACK_BUILD_BENCH=OFF -DFTSTACK_INJECT_LAYER_VIOLATION=${VIOLATION}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(REMOVE_RECURSE "${WORK}")
if(rc EQUAL 0)
  message(FATAL_ERROR "configuration accepted the layer violation '${VIOLATION}'")
endif()
if(NOT err MATCHES "Architecture violation")
  message(FATAL_ERROR "configuration failed for another reason:\n${err}")
endif()
string(REGEX MATCH "Architecture violation[^\n]*" line "${err}")
message(STATUS "refused as it should be: ${line}")
