# Fails when a C or C++ source of the project starts a program through a shell: popen,
# system() or /bin/sh. Programs are spawned with an argument vector (hal/host_sim's
# child_process.hpp; tests/support/run_command.hpp in tests).
# Usage: cmake -DSOURCE_DIR=<project> -P no_shell.cmake
file(GLOB_RECURSE sources LIST_DIRECTORIES false
     ${SOURCE_DIR}/firmware/*.c ${SOURCE_DIR}/firmware/*.h ${SOURCE_DIR}/firmware/*.cpp ${SOURCE_DIR}/firmware/*.hpp
     ${SOURCE_DIR}/hal/*.c ${SOURCE_DIR}/hal/*.h ${SOURCE_DIR}/hal/*.cpp ${SOURCE_DIR}/hal/*.hpp
     ${SOURCE_DIR}/lut_gen/*.c ${SOURCE_DIR}/lut_gen/*.h ${SOURCE_DIR}/lut_gen/*.cpp ${SOURCE_DIR}/lut_gen/*.hpp
     ${SOURCE_DIR}/sim_host/*.c ${SOURCE_DIR}/sim_host/*.h ${SOURCE_DIR}/sim_host/*.cpp ${SOURCE_DIR}/sim_host/*.hpp
     ${SOURCE_DIR}/tests/*.c ${SOURCE_DIR}/tests/*.h ${SOURCE_DIR}/tests/*.cpp ${SOURCE_DIR}/tests/*.hpp)
set(found "")
foreach(f ${sources})
  file(STRINGS ${f} lines REGEX "popen|system\\(|/bin/sh")
  foreach(line ${lines})
    list(APPEND found "${f}: ${line}")
  endforeach()
endforeach()
list(LENGTH sources count)
if(found)
  string(REPLACE ";" "\n" found "${found}")
  message(FATAL_ERROR "shell use in the sources:\n${found}")
endif()
message(STATUS "${count} sources, no popen, system( or /bin/sh")
