# From the host build: cross-build the firmware images of both targets as external
# projects that use this build's lut_gen, in <build>/firmware-<target>/. Sets
# ONESHOT_FIRMWARE_AVAILABLE.
find_program(ONESHOT_ARM_GXX arm-none-eabi-g++)
option(ONESHOT_REQUIRE_FIRMWARE "Fail the configuration when the firmware cannot be cross-built" OFF)
set(ONESHOT_FIRMWARE_AVAILABLE OFF)
if(ONESHOT_BUILD_FIRMWARE AND ONESHOT_ARM_GXX)
  include(ExternalProject)
  set(ONESHOT_FIRMWARE_AVAILABLE ON)
  foreach(target cortex-m0 cortex-m4f)
    set(dir ${PROJECT_BINARY_DIR}/firmware-${target})
    ExternalProject_Add(firmware-${target}
      SOURCE_DIR ${PROJECT_SOURCE_DIR}
      BINARY_DIR ${dir}
      CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchain/arm-none-eabi-${target}.cmake
                 -DCMAKE_BUILD_TYPE=Release -DONESHOT_LUT_GEN=$<TARGET_FILE:lut_gen>
                 -DONESHOT_PLANT=${ONESHOT_PLANT} -DONESHOT_WERROR=${ONESHOT_WERROR}
      INSTALL_COMMAND ""
      BUILD_ALWAYS ON
      DEPENDS lut_gen)
  endforeach()
elseif(ONESHOT_BUILD_FIRMWARE AND ONESHOT_REQUIRE_FIRMWARE)
  message(FATAL_ERROR "ONESHOT_REQUIRE_FIRMWARE is ON but arm-none-eabi-g++ was not found "
                      "(apt-get install gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm)")
elseif(ONESHOT_BUILD_FIRMWARE)
  message(WARNING "arm-none-eabi-g++ not found: firmware images and processor-in-the-loop tests are skipped "
                  "(apt-get install gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm)")
endif()
