# Cross toolchain: Cortex-M0 (ARMv6-M, no FPU, soft float), QEMU machine microbit (nRF51822).
set(ONESHOT_FIRMWARE_TARGET cortex-m0)
set(ONESHOT_CPU_FLAGS "-mcpu=cortex-m0 -mthumb -mfloat-abi=soft")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
