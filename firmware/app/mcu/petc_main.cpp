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
#include "pil_link.hpp"

#if !defined(ONESHOT_MCU_MPS2)
#error "the petc image is built for the Cortex-M4F (MPS2 AN386) only: the node needs ~49 KB of RAM"
#endif

namespace {

using namespace oneshot;
namespace pil = app::pil;
namespace pp = app::petc;
namespace soc = mcu::soc;
using mcu::PilLink;
using Node = pp::Node<float>;

float g_words[pp::kWordCount];
alignas(Node) unsigned char g_node_storage[sizeof(Node)];
Node* g_node = nullptr;

/// The control image's hello layout: cortex-m4f, float, n = 12, m = p = 1.
constexpr pil::ImageInfo kImage{soc::kPilTargetId, 0, 0, pp::kStates, 1, 1};

/// The node's requests (PilRuntime answers kHello, kCalibrate and kEcho); `r` is begun.
void handle(const pil::Frame& q, pil::Frame& r) {
  using pil::malformed;
  pil::Writer w(r);
  pil::Reader in(q);
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
  pil::write_fault(r, pil::kFaultUnknownRequest);
}

}  // namespace

/// No actuation timer in this image.
extern "C" void oneshot_actuation_timer_handler() { soc::ActuationTimer::acknowledge(); }

int main() {
  PilLink::init();
  mcu::interrupts_on();
  PilLink::serve(kImage, handle);
}
