# Cross build of the firmware images (included when CMAKE_CROSSCOMPILING, see toolchain/).
# Every image goes through oneshot_firmware_image() below: the PIL images
# oneshot-<target>-<float|fixed>-<table|nearest|generic>.elf, the C-job-only images, the petc
# image (Cortex-M4F) and the probes that are not part of ALL (heap, size, -Og).
if(NOT ONESHOT_FIRMWARE_TARGET)
  message(FATAL_ERROR "use a toolchain file from toolchain/ (it sets ONESHOT_FIRMWARE_TARGET)")
endif()

# lut_gen is a host tool: take the host build's, or build it natively here.
set(ONESHOT_LUT_GEN "" CACHE FILEPATH "host lut_gen executable (built natively when empty)")
if(ONESHOT_LUT_GEN)
  set(lut_gen_exe ${ONESHOT_LUT_GEN})
  set(lut_gen_dep ${ONESHOT_LUT_GEN})
else()
  include(ExternalProject)
  set(host_dir ${CMAKE_BINARY_DIR}/host_tools)
  ExternalProject_Add(host_tools
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${host_dir}
    CMAKE_ARGS -DCMAKE_BUILD_TYPE=Release -DONESHOT_BUILD_TESTS=OFF -DONESHOT_BUILD_FIRMWARE=OFF
               -DONESHOT_PLANT=${ONESHOT_PLANT}
    BUILD_COMMAND ${CMAKE_COMMAND} --build ${host_dir} --target lut_gen
    INSTALL_COMMAND ""
    BUILD_ALWAYS ON
    BUILD_BYPRODUCTS ${host_dir}/lut_gen/lut_gen)
  set(lut_gen_exe ${host_dir}/lut_gen/lut_gen)
  set(lut_gen_dep host_tools)
endif()

set(generated_dir ${CMAKE_BINARY_DIR}/generated)
include(${PROJECT_SOURCE_DIR}/cmake/oneshot_generated_tables.cmake)
oneshot_generated_tables(LUT_GEN ${lut_gen_exe} TOOL_DEPENDS ${lut_gen_dep} GENERATED_DIR ${generated_dir}
                         REPORT ${CMAKE_BINARY_DIR}/lut_report.json)

# The SoC of each target: its define selects hal/mcu/include/oneshot/mcu/soc.hpp's drivers,
# which hold every interrupt number and board constant; the linker script holds its memory map.
if(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m0")
  set(soc_define ONESHOT_MCU_NRF51)
  set(linker_script ${PROJECT_SOURCE_DIR}/firmware/app/mcu/nrf51_microbit.ld)
elseif(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m4f")
  set(soc_define ONESHOT_MCU_MPS2)
  set(linker_script ${PROJECT_SOURCE_DIR}/firmware/app/mcu/mps2_an386.ld)
else()
  message(FATAL_ERROR "unknown firmware target ${ONESHOT_FIRMWARE_TARGET}")
endif()

# -O3 gives the fewest instructions per job; -Os the smallest flash and stack (see docs/oneshot.md).
set(ONESHOT_FIRMWARE_OPT "-O3" CACHE STRING "optimisation of the firmware images: -O3, -O2 or -Os")
set_property(CACHE ONESHOT_FIRMWARE_OPT PROPERTY STRINGS -O3 -O2 -Os)
if(NOT ONESHOT_FIRMWARE_OPT MATCHES "^-O[23s]$")
  message(FATAL_ERROR "ONESHOT_FIRMWARE_OPT must be -O3, -O2 or -Os (got '${ONESHOT_FIRMWARE_OPT}')")
endif()
set(fw_common_options
  -ffreestanding $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-use-cxa-atexit>
  $<$<COMPILE_LANGUAGE:C>:-pedantic>
  -ffunction-sections -fdata-sections -g ${ONESHOT_FIRMWARE_OPT} -fstack-usage
  -Wall -Wextra -Wconversion -Wsign-conversion -Wshadow -Wdouble-promotion)
# The generated C99 job (lut_gen --c-job-dir), compiled as strict C99 beside the C++ job.
set(c_job_source ${generated_dir}/oneshot_c/oneshot_job.c)
set_source_files_properties(${c_job_source} PROPERTIES GENERATED TRUE)
if(ONESHOT_WERROR)
  list(APPEND fw_common_options -Werror)
endif()
# startup.cpp implements memcpy/memset: keep the compiler from turning their loops into calls to themselves.
set_source_files_properties(firmware/app/mcu/startup.cpp PROPERTIES COMPILE_OPTIONS "-fno-builtin;-fno-tree-loop-distribute-patterns")

# The sources of the PIL images of main.cpp that read none of an image's defines (startup, the
# PIL link, the generated C99 job with every variant) compile once per target, with the same
# flags, into these objects: the six images link the same objects they compiled each before
# (five compiles of the C job, pil_link.cpp and startup.cpp fewer per target).
add_library(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} OBJECT
  firmware/app/mcu/startup.cpp firmware/app/mcu/pil_link.cpp ${c_job_source})
set_target_properties(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
add_dependencies(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} oneshot_generated)
target_include_directories(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} PRIVATE firmware/core/include hal/mcu/include
                           firmware/app/include hal/include ${generated_dir} ${generated_dir}/oneshot_c)
target_compile_options(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} PRIVATE ${fw_common_options})
target_compile_definitions(oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET} PRIVATE ${soc_define})

# oneshot_firmware_image(<image> SOURCES <src>... [C_JOB] [PIL] [PIL_COMMON] [EXCLUDE_FROM_ALL]
#                        [STACK_BOUND] [INCLUDES <dir>...] [DEFINES <def>...] [OPTIONS <opt>...])
# One firmware image <image>.elf for ONESHOT_FIRMWARE_TARGET: SOURCES with startup.cpp, the
# SoC's define and linker script, the firmware flags (OPTIONS replaces them), -nostdlib (libgcc
# only, so any heap use fails the link), its size printed after the link. C_JOB adds the
# generated tables and C99 job; PIL the PIL link (pil_link.cpp: the runtime's vectors and
# assert handler); PIL_COMMON (with C_JOB and PIL, the firmware flags) takes startup, the PIL
# link and the C job from the target's shared objects above; STACK_BOUND writes
# <image>.elf.stack.txt, the sum of every frame in the image's own objects (-fstack-usage; no
# recursion, so no call chain can need more): never with PIL_COMMON.
function(oneshot_firmware_image image)
  cmake_parse_arguments(PARSE_ARGV 1 arg "C_JOB;PIL;PIL_COMMON;EXCLUDE_FROM_ALL;STACK_BOUND" "" "SOURCES;INCLUDES;DEFINES;OPTIONS")
  set(includes firmware/core/include hal/mcu/include ${arg_INCLUDES})
  if(arg_PIL_COMMON)
    if(NOT arg_C_JOB OR NOT arg_PIL OR arg_STACK_BOUND OR DEFINED arg_OPTIONS)
      message(FATAL_ERROR "oneshot_firmware_image(${image}): PIL_COMMON needs C_JOB and PIL, the firmware flags, no STACK_BOUND")
    endif()
    # The image's own sources compile in an object library too: the link takes them first, in
    # the order the image compiled them before (its own sources, startup, the PIL link, the job).
    set(compiled ${image}-objects)
    add_library(${compiled} OBJECT ${arg_SOURCES})
    set(sources $<TARGET_OBJECTS:${compiled}> $<TARGET_OBJECTS:oneshot-pil-common-${ONESHOT_FIRMWARE_TARGET}>)
  else()
    set(compiled ${image})
    set(sources ${arg_SOURCES} firmware/app/mcu/startup.cpp)
    if(arg_PIL)
      list(APPEND sources firmware/app/mcu/pil_link.cpp)
    endif()
    if(arg_C_JOB)
      list(APPEND sources ${c_job_source})
    endif()
  endif()
  if(arg_PIL)
    list(APPEND includes firmware/app/include hal/include)
  endif()
  if(arg_C_JOB)
    list(APPEND includes ${generated_dir} ${generated_dir}/oneshot_c)
  endif()
  set(exclude)
  if(arg_EXCLUDE_FROM_ALL)
    set(exclude EXCLUDE_FROM_ALL)
  endif()
  add_executable(${image} ${exclude} ${sources})
  set_target_properties(${image} PROPERTIES SUFFIX ".elf" C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF
                                            LINKER_LANGUAGE CXX)
  if(arg_C_JOB)
    add_dependencies(${compiled} oneshot_generated)
  endif()
  target_include_directories(${compiled} PRIVATE ${includes})
  if(DEFINED arg_OPTIONS)
    target_compile_options(${compiled} PRIVATE ${arg_OPTIONS})
  else()
    target_compile_options(${compiled} PRIVATE ${fw_common_options})
  endif()
  target_compile_definitions(${compiled} PRIVATE ${soc_define} ${arg_DEFINES})
  target_link_options(${image} PRIVATE -nostdlib -T ${linker_script} -L ${PROJECT_SOURCE_DIR}/firmware/app/mcu
                      -Wl,--gc-sections -Wl,-Map=$<TARGET_FILE:${image}>.map)
  target_link_libraries(${image} PRIVATE gcc)
  set(post COMMAND arm-none-eabi-size $<TARGET_FILE:${image}>)
  if(arg_STACK_BOUND)
    list(APPEND post COMMAND ${CMAKE_COMMAND} -DDIR=${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/${image}.dir
                     -DOUT=$<TARGET_FILE:${image}>.stack.txt -P ${PROJECT_SOURCE_DIR}/cmake/oneshot_stack_bound.cmake)
  endif()
  add_custom_command(TARGET ${image} POST_BUILD ${post} COMMENT "size of ${image}")
endfunction()

# The defines of firmware/app/mcu/main.cpp for <format> (float, fixed) and <disc> (table,
# nearest, generic), into <out>: the number format, the discretizer, and the generated C jobs
# of approaches 5 (this format and sub-grid policy) and 6 (its own-arithmetic twin: q15 for
# fixed, float_poly for the float table), each as its variant and the header's HAS macro.
function(oneshot_main_defines format disc out)
  set(defs ONESHOT_FW_FIXED=$<STREQUAL:${format},fixed>
           ONESHOT_FW_DISC=$<IF:$<STREQUAL:${disc},generic>,1,$<IF:$<STREQUAL:${disc},nearest>,2,0>>)
  set(main)
  set(own_arith)
  if(NOT disc STREQUAL "generic")
    set(main ${format}_${disc})
    if(format STREQUAL "fixed")
      set(own_arith q15_${disc})
    elseif(disc STREQUAL "table")
      set(own_arith float_poly)
    endif()
  endif()
  foreach(job MAIN OWN_ARITH)
    string(TOLOWER ${job} var)
    if(${var})
      string(TOUPPER ${${var}} upper)
      list(APPEND defs ONESHOT_CJOB_${job}_VARIANT=${${var}} ONESHOT_CJOB_${job}_HAS=ONESHOT_JOB_HAS_${upper})
    endif()
  endforeach()
  set(${out} ${defs} PARENT_SCOPE)
endfunction()

# The PIL images, oneshot-<target>-<float|fixed>-<table|nearest|generic>.elf, each with every
# approach (firmware/app/mcu/main.cpp).
foreach(format float fixed)
  foreach(disc table nearest generic)
    oneshot_main_defines(${format} ${disc} main_defines)
    oneshot_firmware_image(oneshot-${ONESHOT_FIRMWARE_TARGET}-${format}-${disc} C_JOB PIL PIL_COMMON
      SOURCES firmware/app/mcu/main.cpp DEFINES ${main_defines})
  endforeach()
endforeach()

# Job-only images of the generated C job (no PIL link), one per variant, for flash, RAM and
# stack bound: oneshot-<target>-cjob-<variant>.elf.
set(c_job_variants fixed_table fixed_nearest float_table float_nearest q15_table q15_nearest float_poly)
foreach(variant ${c_job_variants})
  string(TOUPPER ${variant} variant_upper)
  set(others ${c_job_variants})
  list(REMOVE_ITEM others ${variant})
  list(TRANSFORM others TOUPPER)
  list(TRANSFORM others PREPEND ONESHOT_JOB_WITHOUT_)
  oneshot_firmware_image(oneshot-${ONESHOT_FIRMWARE_TARGET}-cjob-${variant} C_JOB STACK_BOUND
    SOURCES firmware/app/mcu/c_job_only.cpp
    DEFINES ONESHOT_CJOB_VARIANT=${variant} ONESHOT_CJOB_HAS=ONESHOT_JOB_HAS_${variant_upper} ${others})
endforeach()

# A heap use must fail the link: this probe allocates and is never part of ALL.
oneshot_firmware_image(oneshot-heap-probe-${ONESHOT_FIRMWARE_TARGET} EXCLUDE_FROM_ALL
  SOURCES firmware/app/mcu/heap_probe.cpp OPTIONS -ffreestanding -fno-exceptions -fno-rtti)

# Size probes: one control job (half Kalman, generic float discretizer) for a synthetic dense
# n-state plant, n = ONESHOT_PROBE_N; not part of ALL.
foreach(probe_n RANGE 2 16)
  oneshot_firmware_image(oneshot-${ONESHOT_FIRMWARE_TARGET}-size-probe-n${probe_n} EXCLUDE_FROM_ALL STACK_BOUND
    SOURCES firmware/app/mcu/size_probe.cpp DEFINES ONESHOT_PROBE_N=${probe_n})
endforeach()

# The fixed-point job must link no soft-float routine at any optimisation level (its
# constants are integer-exact): the fixed table image built at -Og, never part of ALL; a
# test builds it and checks its symbols (tests/pil/og_no_floating_point.cmake).
set(og_options ${fw_common_options})
list(REMOVE_ITEM og_options ${ONESHOT_FIRMWARE_OPT} -Werror)
oneshot_main_defines(fixed table og_defines)
oneshot_firmware_image(oneshot-og-probe-${ONESHOT_FIRMWARE_TARGET} EXCLUDE_FROM_ALL C_JOB PIL
  SOURCES firmware/app/mcu/main.cpp OPTIONS ${og_options} -Og DEFINES ${og_defines})

# The petc image (Cortex-M4F only: the node with H = 200 needs ~49 KB of RAM, the nRF51 has 16 KB):
# the PETC controller node behind the PIL link, one NUMRE arrival per request between the
# instruction-count markers (firmware/app/mcu/petc_main.cpp).
if(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m4f")
  oneshot_firmware_image(oneshot-${ONESHOT_FIRMWARE_TARGET}-petc PIL STACK_BOUND
    SOURCES firmware/app/mcu/petc_main.cpp INCLUDES firmware/node/include)
endif()
