/// @file heap_probe.cpp
/// @brief Deliberately allocates: linking it with the firmware flags must fail (no heap).
#include <cstdint>

extern "C" void* malloc(unsigned int size);

extern "C" void oneshot_actuation_timer_handler() {}
extern "C" void oneshot_uart_rx_handler() {}
extern "C" void oneshot_idle_wakeup_handler() {}
extern "C" [[noreturn]] void oneshot_fault_handler() {
  for (;;) {
  }
}

int main() {
  auto* p = static_cast<volatile std::uint8_t*>(malloc(16));
  p[0] = 1;
  return p[0];
}
