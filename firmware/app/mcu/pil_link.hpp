/// @file pil_link.hpp
/// @brief The PIL runtime on this image's SoC (app::pil::PilRuntime over soc.hpp's UART and
///        idle wake-up timer). pil_link.cpp defines, once for every PIL image, the link's
///        interrupt handlers, the fault handler and the failed-invariant report.
#pragma once

#include "oneshot/app/pil_runtime.hpp"
#include "oneshot/mcu/mmio.hpp"
#include "oneshot/mcu/soc.hpp"

namespace oneshot::mcu {

/// The PIL link of this image.
using PilLink = app::pil::PilRuntime<soc::Uart, soc::IdleWakeup, Cpu>;

}  // namespace oneshot::mcu
