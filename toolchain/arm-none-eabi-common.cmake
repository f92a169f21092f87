# What both arm-none-eabi toolchain files share: the compilers, a bare-metal system and the
# CPU flags; the including file sets ONESHOT_FIRMWARE_TARGET and ONESHOT_CPU_FLAGS first.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_FLAGS_INIT "${ONESHOT_CPU_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT "${ONESHOT_CPU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${ONESHOT_CPU_FLAGS}")
