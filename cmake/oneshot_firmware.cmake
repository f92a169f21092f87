# Cross build of the firmware images (included when CMAKE_CROSSCOMPILING, see toolchain/).
# Images: oneshot-<target>-<float|fixed>-<table|generic>.elf, each with every approach.
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

if(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m0")
  set(soc_define ONESHOT_MCU_NRF51)
  set(irq_count 32)
  set(uart_irq 2)
  set(extra_defines)
  set(linker_script ${PROJECT_SOURCE_DIR}/firmware/app/mcu/nrf51_microbit.ld)
elseif(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m4f")
  set(soc_define ONESHOT_MCU_MPS2)
  set(irq_count 48)
  set(uart_irq 0)
  set(extra_defines ONESHOT_MCU_IDLE_IRQ=9)
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

function(oneshot_firmware_link target)
  target_link_options(${target} PRIVATE -nostdlib -T ${linker_script} -L ${PROJECT_SOURCE_DIR}/firmware/app/mcu
                      -Wl,--gc-sections -Wl,-Map=$<TARGET_FILE:${target}>.map)
  target_link_libraries(${target} PRIVATE gcc)
endfunction()

foreach(format float fixed)
  foreach(disc table nearest generic)
    set(image oneshot-${ONESHOT_FIRMWARE_TARGET}-${format}-${disc})
    add_executable(${image} firmware/app/mcu/main.cpp firmware/app/mcu/startup.cpp ${c_job_source})
    set_target_properties(${image} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
    # startup.cpp implements memcpy/memset: keep the compiler from turning their loops into calls to themselves.
    set_source_files_properties(firmware/app/mcu/startup.cpp PROPERTIES COMPILE_OPTIONS "-fno-builtin;-fno-tree-loop-distribute-patterns")
    set_target_properties(${image} PROPERTIES SUFFIX ".elf")
    add_dependencies(${image} oneshot_generated)
    target_include_directories(${image} PRIVATE
      firmware/core/include firmware/app/include hal/include hal/mcu/include ${generated_dir} ${generated_dir}/oneshot_c)
    target_compile_options(${image} PRIVATE ${fw_common_options})
    target_compile_definitions(${image} PRIVATE ${soc_define}
      ONESHOT_MCU_IRQ_COUNT=${irq_count} ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq} ${extra_defines}
      ONESHOT_FW_FIXED=$<STREQUAL:${format},fixed>
      ONESHOT_FW_DISC=$<IF:$<STREQUAL:${disc},generic>,1,$<IF:$<STREQUAL:${disc},nearest>,2,0>>)
    oneshot_firmware_link(${image})
    add_custom_command(TARGET ${image} POST_BUILD
      COMMAND arm-none-eabi-size $<TARGET_FILE:${image}>
      COMMENT "size of ${image}")
  endforeach()
endforeach()

# Job-only images of the generated C job (no PIL link), one per variant, for flash and RAM:
# oneshot-<target>-cjob-<variant>.elf; <image>.stack.txt bounds the stack by the sum of every
# frame in the image (-fstack-usage; no recursion, so no call chain can need more).
foreach(variant fixed_table fixed_nearest float_table float_nearest q15_table q15_nearest float_poly)
  set(image oneshot-${ONESHOT_FIRMWARE_TARGET}-cjob-${variant})
  add_executable(${image} firmware/app/mcu/c_job_only.cpp firmware/app/mcu/startup.cpp ${c_job_source})
  set_target_properties(${image} PROPERTIES SUFFIX ".elf" C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  add_dependencies(${image} oneshot_generated)
  target_include_directories(${image} PRIVATE firmware/core/include ${generated_dir}/oneshot_c)
  target_compile_options(${image} PRIVATE ${fw_common_options})
  string(TOUPPER ${variant} variant_upper)
  set(others fixed_table fixed_nearest float_table float_nearest q15_table q15_nearest float_poly)
  list(REMOVE_ITEM others ${variant})
  list(TRANSFORM others TOUPPER)
  list(TRANSFORM others PREPEND ONESHOT_JOB_WITHOUT_)
  target_compile_definitions(${image} PRIVATE ${soc_define} ONESHOT_MCU_IRQ_COUNT=${irq_count}
    ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq} ${extra_defines}
    ONESHOT_CJOB_VARIANT=${variant} ONESHOT_CJOB_HAS=ONESHOT_JOB_HAS_${variant_upper} ${others})
  oneshot_firmware_link(${image})
  add_custom_command(TARGET ${image} POST_BUILD
    COMMAND arm-none-eabi-size $<TARGET_FILE:${image}>
    COMMAND ${CMAKE_COMMAND} -DDIR=${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/${image}.dir
            -DOUT=$<TARGET_FILE:${image}>.stack.txt -P ${PROJECT_SOURCE_DIR}/cmake/oneshot_stack_bound.cmake
    COMMENT "size and stack bound of ${image}")
endforeach()

# A heap use must fail the link: this probe allocates and is never part of ALL.
add_executable(oneshot-heap-probe-${ONESHOT_FIRMWARE_TARGET} EXCLUDE_FROM_ALL
  firmware/app/mcu/heap_probe.cpp firmware/app/mcu/startup.cpp)
target_compile_options(oneshot-heap-probe-${ONESHOT_FIRMWARE_TARGET} PRIVATE -ffreestanding -fno-exceptions -fno-rtti)
target_compile_definitions(oneshot-heap-probe-${ONESHOT_FIRMWARE_TARGET} PRIVATE
  ONESHOT_MCU_IRQ_COUNT=${irq_count} ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq})
oneshot_firmware_link(oneshot-heap-probe-${ONESHOT_FIRMWARE_TARGET})

# Size probes: one control job (half Kalman, generic float discretizer) for a synthetic dense
# n-state plant, n = ONESHOT_PROBE_N; not part of ALL. <image>.stack.txt bounds its stack.
foreach(probe_n RANGE 2 16)
  set(image oneshot-${ONESHOT_FIRMWARE_TARGET}-size-probe-n${probe_n})
  add_executable(${image} EXCLUDE_FROM_ALL firmware/app/mcu/size_probe.cpp firmware/app/mcu/startup.cpp)
  set_target_properties(${image} PROPERTIES SUFFIX ".elf")
  target_include_directories(${image} PRIVATE firmware/core/include)
  target_compile_options(${image} PRIVATE ${fw_common_options})
  target_compile_definitions(${image} PRIVATE ${soc_define} ONESHOT_MCU_IRQ_COUNT=${irq_count}
    ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq} ${extra_defines} ONESHOT_PROBE_N=${probe_n})
  oneshot_firmware_link(${image})
  add_custom_command(TARGET ${image} POST_BUILD
    COMMAND arm-none-eabi-size $<TARGET_FILE:${image}>
    COMMAND ${CMAKE_COMMAND} -DDIR=${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/${image}.dir
            -DOUT=$<TARGET_FILE:${image}>.stack.txt -P ${PROJECT_SOURCE_DIR}/cmake/oneshot_stack_bound.cmake
    COMMENT "size and stack bound of ${image}")
endforeach()

# The fixed-point job must link no soft-float routine at any optimisation level (its
# constants are integer-exact): the fixed table image built at -Og, never part of ALL; a
# test builds it and checks its symbols (tests/pil/og_no_floating_point.cmake).
set(og_probe oneshot-og-probe-${ONESHOT_FIRMWARE_TARGET})
add_executable(${og_probe} EXCLUDE_FROM_ALL firmware/app/mcu/main.cpp firmware/app/mcu/startup.cpp ${c_job_source})
set_target_properties(${og_probe} PROPERTIES SUFFIX ".elf" C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
add_dependencies(${og_probe} oneshot_generated)
target_include_directories(${og_probe} PRIVATE
  firmware/core/include firmware/app/include hal/include hal/mcu/include ${generated_dir} ${generated_dir}/oneshot_c)
set(og_options ${fw_common_options})
list(REMOVE_ITEM og_options ${ONESHOT_FIRMWARE_OPT} -Werror)
target_compile_options(${og_probe} PRIVATE ${og_options} -Og)
target_compile_definitions(${og_probe} PRIVATE ${soc_define}
  ONESHOT_MCU_IRQ_COUNT=${irq_count} ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq} ${extra_defines}
  ONESHOT_FW_FIXED=1 ONESHOT_FW_DISC=0)
oneshot_firmware_link(${og_probe})

# The petc image (Cortex-M4F only: the node with H = 200 needs ~49 KB of RAM, the nRF51 has 16 KB):
# the PETC controller node behind the PIL link, one NUMRE arrival per request between the
# instruction-count markers (firmware/app/mcu/petc_main.cpp); <image>.stack.txt as above.
if(ONESHOT_FIRMWARE_TARGET STREQUAL "cortex-m4f")
  set(image oneshot-${ONESHOT_FIRMWARE_TARGET}-petc)
  add_executable(${image} firmware/app/mcu/petc_main.cpp firmware/app/mcu/startup.cpp)
  set_target_properties(${image} PROPERTIES SUFFIX ".elf")
  target_include_directories(${image} PRIVATE
    firmware/core/include firmware/app/include firmware/node/include hal/include hal/mcu/include)
  target_compile_options(${image} PRIVATE ${fw_common_options})
  target_compile_definitions(${image} PRIVATE ${soc_define}
    ONESHOT_MCU_IRQ_COUNT=${irq_count} ONESHOT_MCU_ACTUATION_IRQ=8 ONESHOT_MCU_UART_IRQ=${uart_irq} ${extra_defines})
  oneshot_firmware_link(${image})
  add_custom_command(TARGET ${image} POST_BUILD
    COMMAND arm-none-eabi-size $<TARGET_FILE:${image}>
    COMMAND ${CMAKE_COMMAND} -DDIR=${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/${image}.dir
            -DOUT=$<TARGET_FILE:${image}>.stack.txt -P ${PROJECT_SOURCE_DIR}/cmake/oneshot_stack_bound.cmake
    COMMENT "size and stack bound of ${image}")
endif()
