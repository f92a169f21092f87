# Fails when a C, C++ or CMake source of the project starts a program through a shell (the
# C library's pipe-open or command-string call, or the shell's own path). Programs are
# spawned with an argument vector (host_util's child_process.hpp; tests/support/
# run_command.hpp in tests; execute_process and add_custom_command in CMake).
# The pattern is written with bracket classes so that this file does not match itself.
# Usage: cmake -DSOURCE_DIR=<project> -P no_shell.cmake
set(sources "")
foreach(dir firmware hal lut_gen sim_host tests cmake toolchain)
  file(GLOB_RECURSE found_here LIST_DIRECTORIES false
       ${SOURCE_DIR}/${dir}/*.c ${SOURCE_DIR}/${dir}/*.h ${SOURCE_DIR}/${dir}/*.cpp ${SOURCE_DIR}/${dir}/*.hpp
       ${SOURCE_DIR}/${dir}/*.cmake ${SOURCE_DIR}/${dir}/CMakeLists.txt)
  list(APPEND sources ${found_here})
endforeach()
list(APPEND sources ${SOURCE_DIR}/CMakeLists.txt)
set(found "")
foreach(f ${sources})
  file(STRINGS ${f} lines REGEX "p[o]pen|s[y]stem\\(|/bin/[s]h")
  foreach(line ${lines})
    list(APPEND found "${f}: ${line}")
  endforeach()
endforeach()
list(LENGTH sources count)
if(found)
  string(REPLACE ";" "\n" found "${found}")
  message(FATAL_ERROR "shell use in the sources:\n${found}")
endif()
message(STATUS "${count} sources checked: none starts a program through a shell")
