/// @file pil_link.cpp
/// @brief The vectors every PIL image shares (startup.cpp's table names them): UART receive,
///        idle wake-up, faults; and the MCU's oneshot::assert_failed. The image's main defines
///        only the actuation timer's handler and its job dispatch.
#include "oneshot/assert_handler.hpp"
#include "pil_link.hpp"

using oneshot::mcu::PilLink;

/// The UART receive interrupt.
extern "C" void oneshot_uart_rx_handler() { PilLink::on_uart_rx(); }

/// The idle wake-up timer (see soc::IdleWakeup).
extern "C" void oneshot_idle_wakeup_handler() { PilLink::on_idle_wakeup(); }

/// Faults and unexpected interrupts: reported once over the link, then the core stops.
extern "C" [[noreturn]] void oneshot_fault_handler() { PilLink::report_fault(oneshot::app::pil::kFaultHard); }

namespace oneshot {
/// A failed invariant: its line and file reported once over the link, then the core stops.
[[noreturn]] void assert_failed(const char* file, int line, const char* /*expression*/) {
  PilLink::report_assert(file, line);
}
}  // namespace oneshot
