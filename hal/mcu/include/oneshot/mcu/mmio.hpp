/// @file mmio.hpp
/// @brief Memory-mapped register access and the few core instructions the firmware needs.
#pragma once

#include <cstdint>

namespace oneshot::mcu {

/// The 32-bit register at `address`.
inline volatile std::uint32_t& reg(std::uintptr_t address) {
  return *reinterpret_cast<volatile std::uint32_t*>(address);  // NOLINT: hardware register
}

/// NVIC: enable interrupt `irq`.
inline void nvic_enable(unsigned irq) { reg(0xE000E100U) = 1U << irq; }

/// Enables interrupts (PRIMASK = 0).
inline void interrupts_on() { __asm__ volatile("cpsie i" ::: "memory"); }

/// Disables interrupts (PRIMASK = 1); a pending interrupt still ends a WFI.
inline void interrupts_off() { __asm__ volatile("cpsid i" ::: "memory"); }

/// Sleeps until an interrupt.
inline void wait_for_interrupt() { __asm__ volatile("wfi" ::: "memory"); }

/// Compiler barrier.
inline void barrier() { __asm__ volatile("" ::: "memory"); }

/// The core's interrupt mask and sleep as one type, for the templates that take them
/// (app::wait_until_set, app::pil::PilRuntime).
struct Cpu {
  /// See mcu::interrupts_off().
  static void interrupts_off() { mcu::interrupts_off(); }
  /// See mcu::interrupts_on().
  static void interrupts_on() { mcu::interrupts_on(); }
  /// See mcu::wait_for_interrupt().
  static void wait_for_interrupt() { mcu::wait_for_interrupt(); }
};

}  // namespace oneshot::mcu
