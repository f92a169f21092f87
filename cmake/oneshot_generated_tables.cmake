# One rule for the build-time design and table: lut_gen on the configured plant
# (ONESHOT_PLANT, or the reference board) writes the generated header into
# <GENERATED_DIR>/oneshot/generated/ and the report to <REPORT>; target oneshot_generated.
#   oneshot_generated_tables(LUT_GEN exe-or-target TOOL_DEPENDS deps GENERATED_DIR dir REPORT file [ALL])
function(oneshot_generated_tables)
  cmake_parse_arguments(arg "ALL" "LUT_GEN;GENERATED_DIR;REPORT" "TOOL_DEPENDS" ${ARGN})
  set(header ${arg_GENERATED_DIR}/oneshot/generated/plant_tables.hpp)
  if(ONESHOT_PLANT)
    set(plant_args --plant ${ONESHOT_PLANT})
    set(plant_dep ${ONESHOT_PLANT})
  else()
    set(plant_args)
    set(plant_dep ${PROJECT_SOURCE_DIR}/lut_gen/plants/reference_board.json)
  endif()
  add_custom_command(
    OUTPUT ${header} ${arg_REPORT}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${arg_GENERATED_DIR}/oneshot/generated
    COMMAND ${arg_LUT_GEN} ${plant_args} --header ${header} --report ${arg_REPORT}
    DEPENDS ${arg_TOOL_DEPENDS} ${plant_dep}
    COMMENT "lut_gen: design and Phi/Gamma/Qd table")
  if(arg_ALL)
    add_custom_target(oneshot_generated ALL DEPENDS ${header} ${arg_REPORT})
  else()
    add_custom_target(oneshot_generated DEPENDS ${header} ${arg_REPORT})
  endif()
endfunction()
