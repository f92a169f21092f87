/// @file heap_probe.cpp
/// @brief Deliberately allocates: linking it with the firmware flags must fail (no heap).
#include <cstddef>
#include <cstdint>
#include <new>

extern "C" void* malloc(unsigned int size);

/// Where the allocations escape to (so the compiler cannot elide them).
std::uint32_t* volatile g_escape = nullptr;

int main() {
  auto* p = static_cast<volatile std::uint8_t*>(malloc(16));
  p[0] = 1;
  g_escape = new std::uint32_t(7);  // operator new: no definition either
  return p[0];
}
