# Builds the -Og probe image of the fixed-point firmware, then fails when it links any
# software floating-point routine (see no_floating_point.cmake).
# Usage: cmake -DBUILD_DIR=... -DBUILD_TARGET=... -DNM=... -DIMAGE=... -DCHECK=no_floating_point.cmake -P og_no_floating_point.cmake
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${BUILD_TARGET}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cannot build ${BUILD_TARGET}:\n${out}")
endif()
include(${CHECK})
