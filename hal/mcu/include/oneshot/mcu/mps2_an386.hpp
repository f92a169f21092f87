/// @file mps2_an386.hpp
/// @brief MPS2 AN386 (Cortex-M4F) CMSDK APB UART0 and timer 0 drivers.
///
/// Registers from the Cortex-M System Design Kit TRM (ARM DDI0479): APB UART, APB timer.
#pragma once

#include <cstdint>

#include "oneshot/mcu/mmio.hpp"

namespace oneshot::mcu::mps2 {

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

/// CMSDK APB timer 0 at 0x40000000 (IRQ 8): a count-down of a few cycles raises the
/// actuation interrupt.
struct ActuationTimer {
  static constexpr unsigned kIrq = 8;
  static constexpr std::uintptr_t kBase = 0x40000000U;
  static constexpr std::uintptr_t kCtrl = kBase + 0x0U;
  static constexpr std::uintptr_t kValue = kBase + 0x4U;
  static constexpr std::uintptr_t kReload = kBase + 0x8U;
  static constexpr std::uintptr_t kIntClear = kBase + 0xCU;

  /// Stopped, interrupt line enabled in the NVIC.
  static void init() {
    reg(kCtrl) = 0U;
    nvic_enable(kIrq);
  }
  /// Raises the interrupt a few cycles from now.
  static void arm_once() {
    reg(kCtrl) = 0U;
    reg(kReload) = 16U;
    reg(kValue) = 16U;
    reg(kCtrl) = 0x9U;  // enable, interrupt enable
  }
  /// In the handler: stops the timer and clears the interrupt.
  static void acknowledge() {
    reg(kCtrl) = 0U;
    reg(kIntClear) = 1U;
  }
};

/// CMSDK APB timer 1 at 0x40001000 (IRQ 9), armed only while the firmware sleeps for
/// input. QEMU's CMSDK UART model does not wake its main loop when the guest reads a
/// byte, so with the CPU halted the rest of a frame would wait for an unrelated event;
/// a pending timer gives the main loop its next iteration. Stopped before any job runs.
struct IdleWakeup {
  static constexpr unsigned kIrq = 9;
  static constexpr std::uintptr_t kBase = 0x40001000U;
  static constexpr std::uintptr_t kCtrl = kBase + 0x0U;
  static constexpr std::uintptr_t kValue = kBase + 0x4U;
  static constexpr std::uintptr_t kReload = kBase + 0x8U;
  static constexpr std::uintptr_t kIntClear = kBase + 0xCU;

  /// Interrupt line enabled in the NVIC.
  static void init() {
    reg(kCtrl) = 0U;
    nvic_enable(kIrq);
  }
  /// Starts a 1 ms (25 000-cycle) one-shot.
  static void arm() {
    reg(kReload) = 25000U;
    reg(kValue) = 25000U;
    reg(kCtrl) = 0x9U;
  }
  /// Stops it.
  static void disarm() { reg(kCtrl) = 0U; }
  /// In the handler.
  static void acknowledge() {
    reg(kCtrl) = 0U;
    reg(kIntClear) = 1U;
  }
};

}  // namespace oneshot::mcu::mps2
