# Warning set of every oneshot target: oneshot_warnings(<target>).
function(oneshot_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wdouble-promotion
    -Wcast-align -Wold-style-cast)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wuseless-cast)  # GCC only
  endif()
  if(ONESHOT_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
