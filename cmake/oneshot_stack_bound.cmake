# Sums the stack frames of every function in an image's objects (the .su files of
# -fstack-usage under DIR) and writes the total to OUT: with no recursion, an upper bound of
# the deepest call chain. Usage: cmake -DDIR=objects -DOUT=file -P oneshot_stack_bound.cmake
file(GLOB_RECURSE su_files ${DIR}/*.su)
if(NOT su_files)
  message(FATAL_ERROR "no .su files under ${DIR} (compile with -fstack-usage)")
endif()
set(total 0)
foreach(f ${su_files})
  file(STRINGS ${f} lines)
  foreach(line ${lines})
    if(line MATCHES "\t([0-9]+)\t")
      math(EXPR total "${total} + ${CMAKE_MATCH_1}")
    endif()
  endforeach()
endforeach()
file(WRITE ${OUT} "${total}\n")
