/// @file nrf51.hpp
/// @brief nRF51822 (BBC micro:bit, Cortex-M0) UART0 and TIMER0 drivers.
///
/// Registers from the nRF51 Series Reference Manual (UART chapter 29, TIMER chapter 18).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/mcu/mmio.hpp"

namespace oneshot::mcu::nrf51 {

/// Interrupt lines of the nRF51 (the vector table has 16 + kIrqCount entries).
inline constexpr std::size_t kIrqCount = 32;
/// The target's number in the PIL kHello reply.
inline constexpr std::uint8_t kPilTargetId = 0;  // cortex-m0

/// UART0 at 0x40002000 (IRQ 2): polled transmit, interrupt-driven receive.
struct Uart {
  static constexpr unsigned kIrq = 2;
  static constexpr std::uintptr_t kIntenSet = 0x40002000U + 0x304U;
  static constexpr std::uintptr_t kBase = 0x40002000U;
  static constexpr std::uintptr_t kStartRx = kBase + 0x000U;
  static constexpr std::uintptr_t kStartTx = kBase + 0x008U;
  static constexpr std::uintptr_t kRxDrdy = kBase + 0x108U;
  static constexpr std::uintptr_t kTxDrdy = kBase + 0x11CU;
  static constexpr std::uintptr_t kEnable = kBase + 0x500U;
  static constexpr std::uintptr_t kRxd = kBase + 0x518U;
  static constexpr std::uintptr_t kTxd = kBase + 0x51CU;
  static constexpr std::uintptr_t kBaudrate = kBase + 0x524U;

  /// 8N1, 115200 baud, transmitter and receiver started.
  static void init() {
    reg(kEnable) = 4U;
    reg(kBaudrate) = 0x01D7E000U;  // 115200
    reg(kTxDrdy) = 0U;
    reg(kRxDrdy) = 0U;
    reg(kStartTx) = 1U;
    reg(kStartRx) = 1U;
    reg(kIntenSet) = 1U << 2;  // RXDRDY
    nvic_enable(kIrq);
  }
  /// Sends one byte (waits for the transmitter).
  static void put(std::uint8_t b) {
    reg(kTxd) = b;
    while (reg(kTxDrdy) == 0U) {
    }
    reg(kTxDrdy) = 0U;
  }
  /// From the receive interrupt: takes every queued byte. The event is cleared before
  /// RXD is read: reading RXD with more bytes queued raises it again.
  template <typename Sink>
  static void drain(Sink&& sink) {
    while (reg(kRxDrdy) != 0U) {
      reg(kRxDrdy) = 0U;
      sink(static_cast<std::uint8_t>(reg(kRxd) & 0xFFU));
    }
  }
};

/// TIMER0 at 0x40008000 (IRQ 8), compare 0 raises the actuation interrupt.
struct ActuationTimer {
  static constexpr unsigned kIrq = 8;
  static constexpr std::uintptr_t kBase = 0x40008000U;
  static constexpr std::uintptr_t kStart = kBase + 0x000U;
  static constexpr std::uintptr_t kStop = kBase + 0x004U;
  static constexpr std::uintptr_t kClear = kBase + 0x00CU;
  static constexpr std::uintptr_t kCompare0 = kBase + 0x140U;
  static constexpr std::uintptr_t kIntenSet = kBase + 0x304U;
  static constexpr std::uintptr_t kMode = kBase + 0x504U;
  static constexpr std::uintptr_t kBitmode = kBase + 0x508U;
  static constexpr std::uintptr_t kPrescaler = kBase + 0x510U;
  static constexpr std::uintptr_t kCc0 = kBase + 0x540U;

  /// Timer mode, 32 bit, 16 MHz, compare-0 interrupt enabled.
  static void init() {
    reg(kMode) = 0U;
    reg(kBitmode) = 3U;
    reg(kPrescaler) = 0U;
    reg(kIntenSet) = 1U << 16;
    nvic_enable(kIrq);
  }
  /// Raises the interrupt one timer tick from now.
  static void arm_once() {
    reg(kStop) = 1U;
    reg(kClear) = 1U;
    reg(kCc0) = 1U;
    reg(kStart) = 1U;
  }
  /// In the handler: stops the timer and clears the event.
  static void acknowledge() {
    reg(kStop) = 1U;
    reg(kCompare0) = 0U;
  }
};

/// The nRF51 UART model wakes QEMU on every byte read: nothing to do while idle.
struct IdleWakeup {
  static constexpr bool kHasIrq = false;  ///< No interrupt line, no vector.
  static constexpr unsigned kIrq = 0;     ///< Unused.
  static void init() {}
  static void arm() {}
  static void disarm() {}
  static void acknowledge() {}
};

}  // namespace oneshot::mcu::nrf51
