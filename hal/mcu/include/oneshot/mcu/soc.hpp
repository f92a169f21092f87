/// @file soc.hpp
/// @brief The SoC of this image, selected by the build (ONESHOT_MCU_NRF51 or ONESHOT_MCU_MPS2),
///        as namespace oneshot::mcu::soc: its drivers, interrupt numbers and PIL target id.
///        The one place the firmware learns its board constants (startup.cpp's vector table,
///        the PIL runtime's link).
#pragma once

#if defined(ONESHOT_MCU_NRF51)
#include "oneshot/mcu/nrf51.hpp"
namespace oneshot::mcu {
namespace soc = nrf51;
}  // namespace oneshot::mcu
#elif defined(ONESHOT_MCU_MPS2)
#include "oneshot/mcu/mps2_an386.hpp"
namespace oneshot::mcu {
namespace soc = mps2;
}  // namespace oneshot::mcu
#else
#error "define ONESHOT_MCU_NRF51 or ONESHOT_MCU_MPS2"
#endif
