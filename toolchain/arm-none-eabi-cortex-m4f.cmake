# Cross toolchain: Cortex-M4F (ARMv7E-M, single-precision FPU, hard float), QEMU machine mps2-an386.
set(ONESHOT_FIRMWARE_TARGET cortex-m4f)
set(ONESHOT_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
