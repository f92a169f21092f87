# Unity builds of the host libraries (oneshot_sim, oneshot_engine, oneshot_design) and of the test
# executables: their sources compile in groups of a few files, one compiler run per group, so the
# headers they share (the engine, the firmware node templates, json, GoogleTest) are parsed and
# their templates instantiated once per group. Measured on four ncs sources (study, faults, table,
# traces): 59.1 s of compile apart, 31.9 s as one group; the lut_gen and engine test executables
# 245 s of CPU one source at a time, 159 s in groups of four, 145 s in groups of six. Groups follow each folder's source order
# (a study's sources stay together); sources with their own compile definitions compile alone
# (CMake leaves them out of groups), as do the sources named in ONESHOT_UNITY_ALONE (the long
# instantiation-heavy ones: grouping them would put them on the critical path of a two-core
# build). The names a source keeps in its anonymous namespace (and its file-scope `using
# namespace`) must then be unique within its group. ONESHOT_UNITY=OFF compiles every source alone.
option(ONESHOT_UNITY "Compile the host libraries' and the tests' sources in unity groups" ON)
set(ONESHOT_UNITY_GROUP_SIZE 4 CACHE STRING "Sources per unity group of the host libraries")
set(ONESHOT_TEST_UNITY_GROUP_SIZE 6 CACHE STRING "Sources per unity group of a test executable")

# oneshot_unity_groups(<target> <prefix> [SIZE <n>] <source>...): the sources, in order, into the
# target's unity groups <prefix>_0, <prefix>_1, ... of <n> sources each (default
# ONESHOT_UNITY_GROUP_SIZE).
function(oneshot_unity_groups target prefix)
  if(NOT ONESHOT_UNITY)
    return()
  endif()
  cmake_parse_arguments(U "" "SIZE" "" ${ARGN})
  if(NOT U_SIZE)
    set(U_SIZE ${ONESHOT_UNITY_GROUP_SIZE})
  endif()
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE GROUP)
  set(i 0)
  foreach(source IN LISTS U_UNPARSED_ARGUMENTS)
    get_filename_component(name ${source} NAME)
    if(name IN_LIST ONESHOT_UNITY_ALONE)
      continue()
    endif()
    math(EXPR group "${i} / ${U_SIZE}")
    set_source_files_properties(${source} TARGET_DIRECTORY ${target} PROPERTIES UNITY_GROUP "${prefix}_${group}")
    math(EXPR i "${i} + 1")
  endforeach()
endfunction()

# Sources that compile alone: each is a large product of template instantiations on its own.
set(ONESHOT_UNITY_ALONE simulation_runtime_float.cpp simulation_runtime_double.cpp table_builder.cpp)
