# The generated C99 job (lut_gen --c-job-dir) against the C++ core, bit for bit:
#   CJob.Reference                 the C++ core writes long random job sequences (fixture); the
#                                  q15 variants' and float_poly's sequences come from the generated C itself, and
#                                  must stay within stated tolerances of the double core
#   CJob.HostGccBitIdentical       the job compiled by the host C compiler as strict C99
#   CJob.DivisionFreeReciprocal    the reciprocal without division against the core's algorithm
#   CJob.Q15Arithmetic             the q15 variant's saturation, reciprocal and rounding rules
#   CJob.FloatIntegerHelpers       the float variants' integer multiply, conversions and comparison
#                                  against the host's IEEE single arithmetic
#   CJob.HostGccBitIdenticalIntegerFloat  CJob.HostGccBitIdentical with the Cortex-M0's integer
#                                  helpers (ONESHOT_JOB_INTEGER_FLOAT) compiled in
#   CJob.AvrSimavrBitIdentical     the job compiled by avr-gcc (16-bit int) and run in simavr,
#                                  with the cycles per job
set(c_job_dir ${ONESHOT_GENERATED_DIR}/oneshot_c)
set_source_files_properties(${c_job_dir}/oneshot_job.c ${c_job_dir}/oneshot_job.h PROPERTIES GENERATED TRUE)
set(c_job_ref ${CMAKE_CURRENT_BINARY_DIR}/c_job_reference.txt)
set(c_job_strict -pedantic -Wall -Wextra -Wconversion -Werror)

add_executable(c_job_reference c_job/c_job_reference.cpp)
target_link_libraries(c_job_reference PRIVATE oneshot_plant oneshot_host_port oneshot_c_job)
oneshot_warnings(c_job_reference)

add_executable(c_job_check c_job/c_job_check.c ${c_job_dir}/oneshot_job.c)
add_executable(c_job_division_check c_job/c_job_division_check.c)
add_executable(c_job_q15_check c_job/c_job_q15_check.c)
add_executable(c_job_float_check c_job/c_job_float_check.c)
add_executable(c_job_check_integer_float c_job/c_job_check.c ${c_job_dir}/oneshot_job.c)
target_compile_definitions(c_job_check_integer_float PRIVATE ONESHOT_JOB_INTEGER_FLOAT=1)
foreach(t c_job_check c_job_division_check c_job_q15_check c_job_float_check c_job_check_integer_float)
  set_target_properties(${t} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  target_include_directories(${t} PRIVATE ${c_job_dir} ${CMAKE_CURRENT_SOURCE_DIR}/c_job)
  target_compile_options(${t} PRIVATE ${c_job_strict})
  add_dependencies(${t} oneshot_generated)
endforeach()

add_test(NAME CJob.Reference COMMAND c_job_reference ${c_job_ref} 4000)
set_tests_properties(CJob.Reference PROPERTIES FIXTURES_SETUP c_job_reference TIMEOUT 120)
add_test(NAME CJob.HostGccBitIdentical COMMAND c_job_check ${c_job_ref})
set_tests_properties(CJob.HostGccBitIdentical PROPERTIES FIXTURES_REQUIRED c_job_reference TIMEOUT 120)
add_test(NAME CJob.DivisionFreeReciprocal COMMAND c_job_division_check)
add_test(NAME CJob.FloatIntegerHelpers COMMAND c_job_float_check)
set_tests_properties(CJob.FloatIntegerHelpers PROPERTIES TIMEOUT 120)
add_test(NAME CJob.HostGccBitIdenticalIntegerFloat COMMAND c_job_check_integer_float ${c_job_ref})
set_tests_properties(CJob.HostGccBitIdenticalIntegerFloat PROPERTIES FIXTURES_REQUIRED c_job_reference TIMEOUT 120)
add_test(NAME CJob.Q15Arithmetic COMMAND c_job_q15_check)
set_tests_properties(CJob.Q15Arithmetic PROPERTIES TIMEOUT 60)
set_tests_properties(CJob.DivisionFreeReciprocal PROPERTIES TIMEOUT 120)

# avr-gcc + simavr: required by the ci preset (ONESHOT_REQUIRE_AVR), skipped elsewhere when missing.
# The asan preset turns the AVR runs off (ONESHOT_BUILD_AVR): the job runs inside simavr, not in
# sanitized host code, so the ci stage's run already checks all they check.
option(ONESHOT_REQUIRE_AVR "Fail the configuration when avr-gcc or libsimavr is missing" OFF)
option(ONESHOT_BUILD_AVR "Build the AVR job image and run it in simavr (when avr-gcc and libsimavr are found)" ON)
find_program(ONESHOT_AVR_GCC avr-gcc)
find_library(ONESHOT_SIMAVR_LIBRARY simavr)
find_path(ONESHOT_SIMAVR_INCLUDE sim_avr.h PATH_SUFFIXES simavr)
set(c_job_avr_mcu atmega1284)
if(NOT ONESHOT_BUILD_AVR)
  # Nothing: the stage that builds the AVR runs has them.
elseif(ONESHOT_AVR_GCC AND ONESHOT_SIMAVR_LIBRARY AND ONESHOT_SIMAVR_INCLUDE)
  set(avr_elf ${CMAKE_CURRENT_BINARY_DIR}/c_job_avr.elf)
  add_custom_command(
    OUTPUT ${avr_elf}
    COMMAND ${ONESHOT_AVR_GCC} -mmcu=${c_job_avr_mcu} -std=c99 ${c_job_strict} -O2 -ffunction-sections
            -fdata-sections -Wl,--gc-sections -I${c_job_dir}
            ${CMAKE_CURRENT_SOURCE_DIR}/c_job/avr/c_job_avr_main.c ${c_job_dir}/oneshot_job.c -o ${avr_elf} -lm
    DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/c_job/avr/c_job_avr_main.c ${c_job_dir}/oneshot_job.c
            ${c_job_dir}/oneshot_job.h oneshot_generated
    COMMENT "avr-gcc: the generated C job for the ${c_job_avr_mcu} (simavr)")
  add_custom_target(c_job_avr_image ALL DEPENDS ${avr_elf})
  add_executable(c_job_avr_harness c_job/avr/c_job_avr_harness.c)
  target_include_directories(c_job_avr_harness PRIVATE ${ONESHOT_SIMAVR_INCLUDE})
  target_link_libraries(c_job_avr_harness PRIVATE ${ONESHOT_SIMAVR_LIBRARY})
  target_compile_options(c_job_avr_harness PRIVATE -Wall -Wextra)
  add_dependencies(c_job_avr_harness c_job_avr_image)
  add_test(NAME CJob.AvrSimavrBitIdentical COMMAND c_job_avr_harness ${avr_elf} ${c_job_avr_mcu} ${c_job_ref} 4000)
  set_tests_properties(CJob.AvrSimavrBitIdentical PROPERTIES FIXTURES_REQUIRED c_job_reference TIMEOUT 300)
  # The tables in program memory through ONESHOT_CONST_TABLE = __flash (GNU C; avr-gcc 5.4's
  # -Wuninitialized wrongly flags initialised __flash data, hence -Wno-uninitialized).
  set(avr_flash_elf ${CMAKE_CURRENT_BINARY_DIR}/c_job_avr_flash.elf)
  add_custom_command(
    OUTPUT ${avr_flash_elf}
    COMMAND ${ONESHOT_AVR_GCC} -mmcu=${c_job_avr_mcu} -std=gnu99 -Wall -Wextra -Wconversion -Werror -Wno-uninitialized
            -O2 -ffunction-sections -fdata-sections -Wl,--gc-sections -I${c_job_dir} -DONESHOT_CONST_TABLE=__flash
            ${CMAKE_CURRENT_SOURCE_DIR}/c_job/avr/c_job_avr_main.c ${c_job_dir}/oneshot_job.c -o ${avr_flash_elf} -lm
    DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/c_job/avr/c_job_avr_main.c ${c_job_dir}/oneshot_job.c
            ${c_job_dir}/oneshot_job.h oneshot_generated
    COMMENT "avr-gcc: the generated C job with its tables in flash (__flash)")
  add_custom_target(c_job_avr_flash_image ALL DEPENDS ${avr_flash_elf})
  add_dependencies(c_job_avr_harness c_job_avr_flash_image)
  add_test(NAME CJob.AvrSimavrFlashTables COMMAND c_job_avr_harness ${avr_flash_elf} ${c_job_avr_mcu} ${c_job_ref} 1000)
  set_tests_properties(CJob.AvrSimavrFlashTables PROPERTIES FIXTURES_REQUIRED c_job_reference TIMEOUT 300)
elseif(ONESHOT_REQUIRE_AVR)
  message(FATAL_ERROR "ONESHOT_REQUIRE_AVR is ON but avr-gcc or libsimavr was not found "
                      "(apt-get install gcc-avr avr-libc simavr libsimavr-dev)")
else()
  add_test(NAME CJob.AvrSimavrBitIdentical
           COMMAND ${CMAKE_COMMAND} -E echo "skipped: avr-gcc or libsimavr not installed (apt-get install gcc-avr avr-libc simavr libsimavr-dev)")
  set_tests_properties(CJob.AvrSimavrBitIdentical PROPERTIES SKIP_REGULAR_EXPRESSION "skipped:")
endif()
