/// @file wait_until_set.hpp
/// @brief Sleeping until an interrupt handler sets a flag, without sleeping through it.
///
/// Testing the flag and then executing WFI with interrupts enabled loses the wake-up when
/// the interrupt arrives between the two: its handler sets the flag, and WFI then waits
/// for an interrupt that has already come. The flag is therefore tested with interrupts
/// masked (PRIMASK): a pending interrupt still ends WFI on Cortex-M, and its handler runs
/// as soon as interrupts are unmasked, before the flag is tested again.
#pragma once

namespace oneshot::app {

/// Waits until `flag` is true. Cpu provides interrupts_off() (cpsid i), interrupts_on()
/// (cpsie i) and wait_for_interrupt() (wfi). Returns with interrupts enabled.
template <typename Cpu>
void wait_until_set(const volatile bool& flag) {
  Cpu::interrupts_off();
  while (!flag) {
    Cpu::wait_for_interrupt();  // ends on a pending interrupt, masked or not
    Cpu::interrupts_on();       // the pending handler runs here
    Cpu::interrupts_off();
  }
  Cpu::interrupts_on();
}

}  // namespace oneshot::app
