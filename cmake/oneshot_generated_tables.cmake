# One rule for the build-time design and table: lut_gen on the configured plant
# (ONESHOT_PLANT, or the reference board) writes the generated header into
# <GENERATED_DIR>/oneshot/generated/, the C99 job (oneshot_job.h/.c) into
# <GENERATED_DIR>/oneshot_c/ and the report to <REPORT>; target oneshot_generated.
#   oneshot_generated_tables(LUT_GEN exe-or-target TOOL_DEPENDS deps GENERATED_DIR dir REPORT file [ALL])
function(oneshot_generated_tables)
  cmake_parse_arguments(arg "ALL" "LUT_GEN;GENERATED_DIR;REPORT" "TOOL_DEPENDS" ${ARGN})
  set(header ${arg_GENERATED_DIR}/oneshot/generated/plant_tables.hpp)
  set(c_job_dir ${arg_GENERATED_DIR}/oneshot_c)
  set(c_job ${c_job_dir}/oneshot_job.h ${c_job_dir}/oneshot_job.c)
  if(ONESHOT_PLANT)
    set(plant_args --plant ${ONESHOT_PLANT})
    set(plant_dep ${ONESHOT_PLANT})
  else()
    set(plant_args)
    set(plant_dep ${PROJECT_SOURCE_DIR}/lut_gen/plants/reference_board.json)
  endif()
  add_custom_command(
    OUTPUT ${header} ${arg_REPORT} ${c_job}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${arg_GENERATED_DIR}/oneshot/generated ${c_job_dir}
    COMMAND ${arg_LUT_GEN} ${plant_args} --header ${header} --report ${arg_REPORT} --c-job-dir ${c_job_dir}
    DEPENDS ${arg_TOOL_DEPENDS} ${plant_dep}
    COMMENT "lut_gen: design and Phi/Gamma/Qd table")
  if(arg_ALL)
    add_custom_target(oneshot_generated ALL DEPENDS ${header} ${arg_REPORT} ${c_job})
  else()
    add_custom_target(oneshot_generated DEPENDS ${header} ${arg_REPORT} ${c_job})
  endif()
endfunction()
