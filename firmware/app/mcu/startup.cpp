/// @file startup.cpp
/// @brief Vector table, reset handler and the C library functions the compiler may call.
///
/// The images link with -nostdlib (only libgcc): there is no malloc, so any heap use
/// fails the link, and no C++ runtime beyond static constructors.
#include <cstddef>
#include <cstdint>

#include "oneshot/mcu/soc.hpp"  // the interrupt numbers of this image's SoC

extern "C" {
extern std::uint32_t __data_load;
extern std::uint32_t __data_start;
extern std::uint32_t __data_end;
extern std::uint32_t __bss_start;
extern std::uint32_t __bss_end;
extern std::uint32_t __stack_top;
using InitFunction = void (*)();
extern InitFunction __init_array_start[];
extern InitFunction __init_array_end[];

int main();
void oneshot_actuation_timer_handler();
void oneshot_uart_rx_handler();
void oneshot_idle_wakeup_handler();
[[noreturn]] void oneshot_fault_handler();

/// Word written over the free stack at reset; the deepest overwritten word is the peak.
constexpr std::uint32_t kStackPaint = 0x5AC3A53CU;

/// Deepest stack use since reset (bytes), found by scanning the paint from below.
std::uint32_t oneshot_stack_peak_bytes() {
  const std::uint32_t* p = &__bss_end;
  while (p < &__stack_top && *p == kStackPaint) ++p;
  return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(&__stack_top) - reinterpret_cast<std::uintptr_t>(p));
}

/// Reset: paint the free stack, copy .data, clear .bss, enable the FPU (M4F), run
/// constructors, main().
[[noreturn]] void reset_handler() {
  {
    // Everything between .bss and this frame (less a margin for it) is free stack.
    std::uintptr_t sp = 0;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (auto* p = reinterpret_cast<volatile std::uint32_t*>(&__bss_end); reinterpret_cast<std::uintptr_t>(p) + 64U < sp; ++p) {
      *p = kStackPaint;
    }
  }
  std::uint32_t* dst = &__data_start;
  const std::uint32_t* src = &__data_load;
  while (dst < &__data_end) *dst++ = *src++;
  for (std::uint32_t* p = &__bss_start; p < &__bss_end; ++p) *p = 0;
#if defined(__ARM_FP)
  // CPACR: full access to CP10 and CP11 before any floating-point instruction.
  *reinterpret_cast<volatile std::uint32_t*>(0xE000ED88U) |= 0xFU << 20;
  __asm__ volatile("dsb\n isb" ::: "memory");
#endif
  for (InitFunction* f = __init_array_start; f < __init_array_end; ++f) (*f)();
  main();
  for (;;) {
  }
}

/// Unexpected interrupts and faults.
void default_handler() { oneshot_fault_handler(); }

/// The vectors an image may leave out (weak: the image's definition wins). The PIL images
/// define them all (pil_link.cpp and their main); the job-only images and the probes have
/// no link, so there an interrupt does nothing and a fault stops the core.
__attribute__((weak)) void oneshot_actuation_timer_handler() {}
/// See oneshot_actuation_timer_handler().
__attribute__((weak)) void oneshot_uart_rx_handler() {}
/// See oneshot_actuation_timer_handler().
__attribute__((weak)) void oneshot_idle_wakeup_handler() {}
/// See oneshot_actuation_timer_handler().
[[noreturn]] __attribute__((weak)) void oneshot_fault_handler() {
  for (;;) {
  }
}

/// Freestanding C library pieces the compiler may emit calls to.
void* memcpy(void* d, const void* s, std::size_t n) {
  auto* dp = static_cast<unsigned char*>(d);
  const auto* sp = static_cast<const unsigned char*>(s);
  if (((reinterpret_cast<std::uintptr_t>(dp) | reinterpret_cast<std::uintptr_t>(sp)) & 3U) == 0U) {
    auto* dw = reinterpret_cast<std::uint32_t*>(dp);
    const auto* sw = reinterpret_cast<const std::uint32_t*>(sp);
    for (; n >= 4; n -= 4) *dw++ = *sw++;
    dp = reinterpret_cast<unsigned char*>(dw);
    sp = reinterpret_cast<const unsigned char*>(sw);
  }
  while (n-- > 0) *dp++ = *sp++;
  return d;
}
void* memmove(void* d, const void* s, std::size_t n) {
  auto* dp = static_cast<unsigned char*>(d);
  const auto* sp = static_cast<const unsigned char*>(s);
  if (dp < sp) {
    while (n-- > 0) *dp++ = *sp++;
  } else {
    while (n-- > 0) dp[n] = sp[n];
  }
  return d;
}
void* memset(void* d, int c, std::size_t n) {
  auto* dp = static_cast<unsigned char*>(d);
  if ((reinterpret_cast<std::uintptr_t>(dp) & 3U) == 0U) {
    const std::uint32_t w = 0x01010101U * static_cast<unsigned char>(c);
    auto* dw = reinterpret_cast<std::uint32_t*>(dp);
    for (; n >= 4; n -= 4) *dw++ = w;
    dp = reinterpret_cast<unsigned char*>(dw);
  }
  while (n-- > 0) *dp++ = static_cast<unsigned char>(c);
  return d;
}
int memcmp(const void* a, const void* b, std::size_t n) {
  const auto* ap = static_cast<const unsigned char*>(a);
  const auto* bp = static_cast<const unsigned char*>(b);
  for (std::size_t i = 0; i < n; ++i)
    if (ap[i] != bp[i]) return ap[i] < bp[i] ? -1 : 1;
  return 0;
}
/// Static objects are never destroyed on bare metal.
int __aeabi_atexit(void*, void (*)(void*), void*) { return 0; }
void* __dso_handle = nullptr;
}

namespace {

using Vector = void (*)();
namespace soc = oneshot::mcu::soc;
constexpr std::size_t kIrqCount = soc::kIrqCount;
constexpr std::size_t kActuationIrq = soc::ActuationTimer::kIrq;
constexpr std::size_t kUartIrq = soc::Uart::kIrq;
static_assert(kActuationIrq < kIrqCount && kUartIrq < kIrqCount && soc::IdleWakeup::kIrq < kIrqCount);
constexpr bool kIdleIrqFree = soc::IdleWakeup::kIrq != kActuationIrq && soc::IdleWakeup::kIrq != kUartIrq;
static_assert(kActuationIrq != kUartIrq && (!soc::IdleWakeup::kHasIrq || kIdleIrqFree), "one vector per interrupt line");

/// Initial stack pointer, then exceptions 1–15 and the SoC interrupts.
struct VectorTable {
  void* stack_top;
  Vector handlers[15 + kIrqCount];
};

constexpr VectorTable make_vectors() {
  VectorTable t{&__stack_top, {}};
  for (Vector& h : t.handlers) h = default_handler;
  t.handlers[0] = reset_handler;                               // 1: reset
  t.handlers[2] = oneshot_fault_handler;                       // 3: hard fault
  t.handlers[15 + kActuationIrq] = oneshot_actuation_timer_handler;  // 16 + irq
  t.handlers[15 + kUartIrq] = oneshot_uart_rx_handler;
  if (soc::IdleWakeup::kHasIrq) t.handlers[15 + soc::IdleWakeup::kIrq] = oneshot_idle_wakeup_handler;
  return t;
}

}  // namespace

/// The vector table, constant-initialised into flash at address 0.
extern "C" __attribute__((section(".vectors"), used)) const VectorTable g_vectors = make_vectors();
