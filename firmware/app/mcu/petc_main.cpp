/// @file petc_main.cpp
/// @brief The petc image (Cortex-M4F, single-precision float on the FPU): the PETC controller
///        node of numre-petc.md behind the PIL link, one NUMRE arrival (prediction over N periods
///        from the span table, Joseph correction, controller trigger, the cascade of H + 1
///        inputs when it sends) between the
///        instruction-count markers per kPetcArrival (oneshot/app/petc_pil.hpp).
#include <cstddef>
#include <cstdint>
#include <new>

#include "oneshot/app/petc_pil.hpp"
#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/assert_handler.hpp"
#include "oneshot/mcu/mps2_an386.hpp"
#include "oneshot/mcu/rx_ring.hpp"

#if !defined(ONESHOT_MCU_MPS2)
#error "the petc image is built for the Cortex-M4F (MPS2 AN386) only: the node needs ~49 KB of RAM"
#endif

namespace soc = oneshot::mcu::mps2;

/// Instruction-count markers (the same names as the control-job image).
extern "C" __attribute__((noinline, used)) void oneshot_job_begin() { __asm__ volatile("" ::: "memory"); }
/// See oneshot_job_begin().
extern "C" __attribute__((noinline, used)) void oneshot_job_end() { __asm__ volatile("" ::: "memory"); }
/// Deepest stack use since reset, bytes (startup.cpp paints the free stack).
extern "C" std::uint32_t oneshot_stack_peak_bytes();

namespace {

using namespace oneshot;
namespace pil = app::pil;
namespace pp = app::petc;
using Node = pp::Node<float>;

float g_words[pp::kWordCount];
alignas(Node) unsigned char g_node_storage[sizeof(Node)];
Node* g_node = nullptr;
mcu::RxRing g_rx;

/// Next received byte; sleeps until the receive interrupt when there is none.
std::uint8_t next_byte() {
  for (;;) {
    std::uint8_t b = 0;
    mcu::interrupts_off();
    if (g_rx.pop(b)) {
      soc::IdleWakeup::disarm();
      mcu::interrupts_on();
      return b;
    }
    soc::IdleWakeup::arm();
    mcu::wait_for_interrupt();
    soc::Uart::drain([](std::uint8_t c) { g_rx.push(c); });
    mcu::interrupts_on();
  }
}

void send(const pil::Frame& f) {
  std::uint8_t out[2 * (pil::kMaxPayload + 5) + 2];
  const std::size_t n = pil::encode(f, out);
  for (std::size_t i = 0; i < n; ++i) soc::Uart::put(out[i]);
}

/// The control image's hello layout: cortex-m4f, float, n = 12, m = p = 1.
void hello(pil::Frame& r) {
  r.type = static_cast<pil::Type>(static_cast<std::uint8_t>(pil::Type::kHello) | 0x80U);
  pil::Writer w(r);
  w.u(pil::kProtocolVersion, 1);
  w.u(1, 1);  // cortex-m4f
  w.u(0, 1);  // float
  w.u(0, 1);
  w.u(pp::kStates, 1);
  w.u(1, 1);
  w.u(1, 1);
  w.u(oneshot_stack_peak_bytes(), 2);
}

void malformed(pil::Frame& r) {
  r.type = pil::Type::kFault;
  r.length = 0;
  pil::Writer w(r);
  w.u(pil::kFaultMalformedRequest, 4);
}

void handle(const pil::Frame& q, pil::Frame& r) {
  r.seq = q.seq;
  r.type = static_cast<pil::Type>(static_cast<std::uint8_t>(q.type) | 0x80U);
  r.length = 0;
  pil::Writer w(r);
  pil::Reader in(q);
  if (q.type == pil::Type::kHello) {
    if (q.length != 0) return malformed(r);
    return hello(r);
  }
  if (q.type == pil::Type::kCalibrate) {
    if (q.length != 0) return malformed(r);
    oneshot_job_begin();
    oneshot_job_end();
    return;
  }
  if (q.type == pp::kPetcLoad) {
    if (q.length < 2 || (q.length - 2) % 4 != 0) return malformed(r);
    const std::uint32_t first = in.u(2);
    const std::size_t count = (q.length - 2) / 4;
    if (first + count > pp::kWordCount) return malformed(r);
    for (std::size_t i = 0; i < count; ++i) g_words[first + i] = pp::float_of(in.u(4));
    w.u(static_cast<std::uint32_t>(count), 2);
    return;
  }
  if (q.type == pp::kPetcReset) {
    if (q.length != 7) return malformed(r);
    pp::ResetParams p;
    p.ratio = in.u(1);
    p.sample_at_update = in.u(1) != 0;
    p.frozen_noise = in.u(1) != 0;
    p.k_max = in.u(4);
    if (p.ratio == 0) return malformed(r);
    const pp::NodeArgs<float> a = pp::node_args(g_words, p);
    if (!Node::fits(a.model)) return malformed(r);  // a nonzero outside HddStructure
    g_node = new (g_node_storage) Node(a.model, a.acc, a.law, node::ModelDisturbance<float>{}, a.trigger, a.reference);
    w.u(static_cast<std::uint32_t>(sizeof(Node)), 4);
    return;
  }
  if (q.type == pp::kPetcArrival) {
    if (q.length != 8 || g_node == nullptr) return malformed(r);
    const std::uint32_t k = in.u(4);
    const float y = pp::float_of(in.u(4));
    const std::uint64_t before = g_node->macs();
    oneshot_job_begin();
    const node::SendCause cause = g_node->on_arrival(k, y);
    oneshot_job_end();
    w.u(static_cast<std::uint32_t>(cause), 1);
    w.u(g_node->estimator().last_multiplicity(), 4);
    w.u(static_cast<std::uint32_t>(g_node->macs() - before), 4);
    for (std::size_t i = 0; i < pp::kStates; ++i) w.u(pp::bits_of(g_node->estimator().state()[i]), 4);
    return;
  }
  if (q.type == pp::kPetcRead) {
    if (q.length != 3 || g_node == nullptr) return malformed(r);
    const std::uint32_t what = in.u(1);
    const std::uint32_t first = in.u(2);
    if (what > 1 || first > Node::kEntries) return malformed(r);
    const float* src = what == 0 ? g_node->last_cascade() : g_node->last_cascade_d_hat();
    for (std::size_t i = first; i < Node::kEntries && i < first + pp::kWordsPerFrame; ++i) w.u(pp::bits_of(src[i]), 4);
    return;
  }
  r.type = pil::Type::kFault;
  w.u(pil::kFaultUnknownRequest, 4);
}

}  // namespace

extern "C" void oneshot_idle_wakeup_handler() { soc::IdleWakeup::acknowledge(); }
extern "C" void oneshot_uart_rx_handler() {
  soc::Uart::drain([](std::uint8_t b) { g_rx.push(b); });
}
/// No actuation timer in this image.
extern "C" void oneshot_actuation_timer_handler() { soc::ActuationTimer::acknowledge(); }

extern "C" [[noreturn]] void oneshot_fault_handler() {
  pil::Frame f;
  f.type = pil::Type::kFault;
  pil::Writer w(f);
  w.u(pil::kFaultHard, 4);
  send(f);
  for (;;) {
  }
}

namespace oneshot {
[[noreturn]] void assert_failed(const char* file, int line, const char* /*expression*/) {
  pil::Frame f;
  f.type = pil::Type::kFault;
  pil::Writer w(f);
  w.u(static_cast<std::uint32_t>(line), 4);
  for (std::size_t i = 0; file[i] != '\0' && f.length < pil::kMaxPayload; ++i) w.u(static_cast<std::uint8_t>(file[i]), 1);
  send(f);
  for (;;) {
  }
}
}  // namespace oneshot

int main() {
  soc::Uart::init();
  soc::IdleWakeup::init();
  mcu::interrupts_on();
  pil::Frame r;
  hello(r);
  send(r);
  pil::Decoder decoder;
  pil::Frame last_reply;
  bool have_last = false;
  for (;;) {
    if (!decoder.feed(next_byte())) continue;
    const pil::Frame& q = decoder.frame();
    // A repeated sequence number is a retransmission: resend the reply, never rerun the arrival.
    if (have_last && q.seq == last_reply.seq &&
        static_cast<std::uint8_t>(last_reply.type) == (static_cast<std::uint8_t>(q.type) | 0x80U)) {
      send(last_reply);
      continue;
    }
    handle(q, last_reply);
    have_last = true;
    send(last_reply);
  }
}
