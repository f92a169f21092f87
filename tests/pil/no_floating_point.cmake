# Fails when a firmware image links any software floating-point routine (libgcc's
# __aeabi_f*/__aeabi_d* and the comparison helpers): the fixed-point images must use none.
# Usage: cmake -DNM=arm-none-eabi-nm -DIMAGE=path.elf -P no_floating_point.cmake
execute_process(COMMAND ${NM} ${IMAGE} OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cannot read the symbols of ${IMAGE}")
endif()
string(REGEX MATCHALL "__aeabi_[fd][a-z0-9]*|__[a-z]+[sd]f[23]|__aeabi_[il]2[fd]|__aeabi_[fd]2[a-z]+" found "${symbols}")
if(found)
  list(REMOVE_DUPLICATES found)
  message(FATAL_ERROR "${IMAGE} links floating-point routines: ${found}")
endif()
message(STATUS "${IMAGE}: no floating-point routines")
