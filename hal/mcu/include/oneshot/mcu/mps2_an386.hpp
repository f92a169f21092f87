/// @file mps2_an386.hpp
/// @brief MPS2 AN386 (Cortex-M4F) CMSDK APB UART0 and timers 0/1 drivers.
///
/// Registers from the Cortex-M System Design Kit TRM (ARM DDI0479): APB UART, APB timer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/mcu/mmio.hpp"

namespace oneshot::mcu::mps2 {

/// Interrupt lines of the AN386 (the vector table has 16 + kIrqCount entries).
inline constexpr std::size_t kIrqCount = 48;
/// The target's number in the PIL kHello reply.
inline constexpr std::uint8_t kPilTargetId = 1;  // cortex-m4f

/// CMSDK APB UART0 at 0x40004000 (receive IRQ 0): polled transmit, interrupt-driven receive.
struct Uart {
  static constexpr unsigned kIrq = 0;
  static constexpr std::uintptr_t kIntStatus = 0x40004000U + 0xCU;
  static constexpr std::uintptr_t kBase = 0x40004000U;
  static constexpr std::uintptr_t kData = kBase + 0x0U;
  static constexpr std::uintptr_t kState = kBase + 0x4U;
  static constexpr std::uintptr_t kCtrl = kBase + 0x8U;
  static constexpr std::uintptr_t kBaudDiv = kBase + 0x10U;

  /// Transmitter and receiver on, 25 MHz / 217 ≈ 115200 baud.
  static void init() {
    reg(kBaudDiv) = 217U;
    reg(kCtrl) = 0x3U | 0x8U;  // TX, RX, RX interrupt
    nvic_enable(kIrq);
  }
  /// Sends one byte (waits while the transmit buffer is full).
  static void put(std::uint8_t b) {
    while ((reg(kState) & 0x1U) != 0U) {
    }
    reg(kData) = b;
  }
  /// Takes the received byte(s). The interrupt is cleared first: a byte arriving after the
  /// clear raises it again, whereas clearing after the read could swallow that byte's
  /// interrupt and leave the receiver full for ever.
  template <typename Sink>
  static void drain(Sink&& sink) {
    reg(kIntStatus) = 0x2U;
    while ((reg(kState) & 0x2U) != 0U) sink(static_cast<std::uint8_t>(reg(kData) & 0xFFU));
  }
};

/// CMSDK APB timer at kBase raising IRQ kIrq: the register block both timers share.
template <std::uintptr_t kTimerBase, unsigned kTimerIrq>
struct CmsdkTimer {
  static constexpr unsigned kIrq = kTimerIrq;
  static constexpr std::uintptr_t kCtrl = kTimerBase + 0x0U;
  static constexpr std::uintptr_t kValue = kTimerBase + 0x4U;
  static constexpr std::uintptr_t kReload = kTimerBase + 0x8U;
  static constexpr std::uintptr_t kIntClear = kTimerBase + 0xCU;
  static constexpr std::uint32_t kEnableWithInterrupt = 0x9U;

  /// Stopped, interrupt line enabled in the NVIC.
  static void init() {
    reg(kCtrl) = 0U;
    nvic_enable(kIrq);
  }
  /// Counts `cycles` down from now, then raises the interrupt.
  static void start(std::uint32_t cycles) {
    reg(kCtrl) = 0U;
    reg(kReload) = cycles;
    reg(kValue) = cycles;
    reg(kCtrl) = kEnableWithInterrupt;
  }
  /// Stops it.
  static void stop() { reg(kCtrl) = 0U; }
  /// In the handler: stops the timer and clears the interrupt.
  static void acknowledge() {
    stop();
    reg(kIntClear) = 1U;
  }
};

/// Timer 0 at 0x40000000 (IRQ 8): a count-down of a few cycles raises the actuation
/// interrupt.
struct ActuationTimer : CmsdkTimer<0x40000000U, 8> {
  /// Raises the interrupt a few cycles from now.
  static void arm_once() { start(16U); }
};

/// Timer 1 at 0x40001000 (IRQ 9), armed only while the firmware sleeps for input.
/// QEMU's CMSDK UART model does not wake its main loop when the guest reads a byte, so
/// with the CPU halted the rest of a frame would wait for an unrelated event; a pending
/// timer gives the main loop its next iteration. Stopped before any job runs.
struct IdleWakeup : CmsdkTimer<0x40001000U, 9> {
  static constexpr bool kHasIrq = true;  ///< Its vector is oneshot_idle_wakeup_handler.
  /// Starts a 1 ms (25 000-cycle) one-shot.
  static void arm() { start(25000U); }
  /// Stops it.
  static void disarm() { stop(); }
};

}  // namespace oneshot::mcu::mps2
