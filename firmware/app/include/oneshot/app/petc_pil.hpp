/// @file petc_pil.hpp
/// @brief The petc controller node as the Cortex-M4F image runs it (numre-petc.md §4–5),
///        and the PIL requests that load it and run one arrival between the
///        instruction-count markers. Shared by the image (firmware/app/mcu/petc_main.cpp)
///        and the host (`oneshot-sim petc exectime`), so both build the same node the same way.
///
/// The image holds the node code only: the HDD plant's constants come from the host's design
/// step (the plant file, lut_gen/plants/hdd_numre.json) as raw IEEE single words over the link
/// (kPetcLoad), the node is then built in place (kPetcReset) and each kPetcArrival runs
/// PetcController::on_arrival(k, y) once between oneshot_job_begin and oneshot_job_end.
/// Requests (payload little-endian; replies have bit 7 set):
///   kPetcLoad    u16 first word, then up to 23 words        → u16 words stored
///   kPetcReset   u8 ratio m, u8 sample_at_update, u8 frozen noise, u32 k_max → u32 sizeof(node)
///   kPetcArrival u32 k, u32 y (float bits)                   → u8 cause, u32 N, u32 multiply-adds
///                                                              of the arrival, 12 words x̂(k|k)
///   kPetcRead    u8 what (0: cascade inputs, 1: their d̂), u16 first entry
///                                                            → up to 24 words of the packet in
///                                                              force (the last sent cascade)
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/node/petc_controller.hpp"

namespace oneshot::app::petc {

inline constexpr std::size_t kStates = 12;    ///< Augmented HDD model: 10 plant + 2 disturbance states.
inline constexpr std::size_t kHorizon = 200;  ///< H: packets of H + 1 inputs (the brief's default h).

/// The MRCI law of the brief: 1 fast and 2 slow first-order modes.
template <typename S>
using Law = node::InterlacedController<S, 1, 2>;
/// Nonzero structure of the augmented HDD model in the basis the design gives the node
/// (sim_host/petc/petc_modal.hpp: the plant's ten states block-diagonalized, z_p = T_p⁻¹x_p,
/// the disturbance states kept): A' = the plant's five 2 × 2 sections, their coupling column
/// 11 from the disturbance, and the disturbance block; 32 of A's 144 entries, 44 in the
/// closure of its powers. B' in the plant rows but row 1, C' over seven states, C̄' the
/// disturbance output state. kPetcReset refuses a model outside it (Node::fits).
struct HddStructure {
  /// Row masks of A (bit j: A_ij may be nonzero).
  static constexpr std::uint32_t kRows[kStates] = {0x803, 0x001, 0x80C, 0x804, 0x830, 0x830,
                                                   0x8C0, 0x8C0, 0xB00, 0xB00, 0xC00, 0xC00};
  /// Row mask i of A.
  static constexpr std::uint32_t row(std::size_t i) { return kRows[i]; }
  static constexpr std::uint32_t kB = 0x3FD;     ///< B': plant rows but row 1.
  static constexpr std::uint32_t kC = 0x1F3;     ///< C': the sections the output sees (not notch 2's, nor 9).
  static constexpr std::uint32_t kCbar = 0x800;  ///< C̄': the disturbance output state.
};

/// The node of cases 3–5: NUMRE on the augmented model, d̂ = C̄ x̂, the HDD structure.
template <typename S>
using Node = node::PetcController<S, kStates, kHorizon, Law<S>, node::ModelDisturbance<S>, HddStructure>;

/// Indices of the constants in the word block (raw IEEE single).
enum Word : std::size_t {
  kA = 0,                           ///< A, row major (12 × 12).
  kB = kA + kStates * kStates,      ///< B (12).
  kBw = kB + kStates,               ///< B_w (12).
  kC = kBw + kStates,               ///< C (12).
  kCbar = kC + kStates,             ///< C̄ (12).
  kW = kCbar + kStates,             ///< W = σ_w².
  kV,                               ///< V = σ_v².
  kFeedthrough,                     ///< MRCI D.
  kFastResidue,                     ///< Fast mode r.
  kFastPole,                        ///< Fast mode p.
  kSlowResidue0,                    ///< Slow mode 0 r.
  kSlowPole0,                       ///< Slow mode 0 p.
  kSlowResidue1,                    ///< Slow mode 1 r.
  kSlowPole1,                       ///< Slow mode 1 p.
  kSigmaC,                          ///< Controller trigger σ_c.
  kDeltaC,                          ///< Controller trigger δ_c.
  kReference,                       ///< r.
  kWordCount                        ///< Words in the block.
};

inline constexpr auto kPetcLoad = static_cast<pil::Type>(0x10);     ///< Store words of the block.
inline constexpr auto kPetcReset = static_cast<pil::Type>(0x11);    ///< Build the node at rest.
inline constexpr auto kPetcArrival = static_cast<pil::Type>(0x12);  ///< One arrival (counted).
inline constexpr auto kPetcRead = static_cast<pil::Type>(0x13);     ///< Read the last cascade.
inline constexpr std::size_t kWordsPerFrame = (pil::kMaxPayload - 3) / 4;  ///< Words per load / read frame.

/// Integer parameters of kPetcReset.
struct ResetParams {
  std::uint32_t ratio = 2;            ///< MRCI m.
  bool sample_at_update = false;      ///< Slow modes sample e at their own update.
  bool frozen_noise = false;          ///< Printed eq. 13 instead of W_e(N).
  std::uint32_t k_max = kHorizon;     ///< Controller's time-triggered safety.
};

/// float from its IEEE bits.
inline float float_of(std::uint32_t bits) {
  float f = 0;
  __builtin_memcpy(&f, &bits, 4);
  return f;
}
/// IEEE bits of a float.
inline std::uint32_t bits_of(float f) {
  std::uint32_t u = 0;
  __builtin_memcpy(&u, &f, 4);
  return u;
}

/// The NUMRE model from the block.
template <typename S>
constexpr node::NumreModel<S, kStates> model_of(const S (&w)[kWordCount]) {
  node::NumreModel<S, kStates> m;
  for (std::size_t i = 0; i < kStates; ++i) {
    for (std::size_t j = 0; j < kStates; ++j) m.a(i, j) = w[kA + i * kStates + j];
    m.b[i] = w[kB + i];
    m.b_w[i] = w[kBw + i];
    m.c[i] = w[kC + i];
    m.c_bar[i] = w[kCbar + i];
  }
  m.w = w[kW];
  m.v = w[kV];
  return m;
}

/// The MRCI law at rest from the block.
template <typename S>
constexpr Law<S> law_of(const S (&w)[kWordCount], const ResetParams& p) {
  node::InterlacedConfig<S, 1, 2> cfg;
  cfg.feedthrough = w[kFeedthrough];
  cfg.fast[0] = {w[kFastResidue], w[kFastPole]};
  cfg.slow[0] = {w[kSlowResidue0], w[kSlowPole0]};
  cfg.slow[1] = {w[kSlowResidue1], w[kSlowPole1]};
  cfg.ratio = p.ratio;
  cfg.sample_at_update = p.sample_at_update;
  return Law<S>(cfg);
}

/// The controller trigger (eq. 22 + safety) from the block.
template <typename S>
constexpr node::MtmTrigger<S, 1> trigger_of(const S (&w)[kWordCount], const ResetParams& p) {
  return node::MtmTrigger<S, 1>(w[kSigmaC], w[kDeltaC], p.k_max, 0);
}

/// Node arguments in the order of Node<S>'s constructor, for `new (storage) Node<S>(…)`.
template <typename S>
struct NodeArgs {
  node::NumreModel<S, kStates> model;  ///< Model.
  node::NoiseAccumulation acc;         ///< W_e(N) or the printed form.
  Law<S> law;                          ///< Law at rest.
  node::MtmTrigger<S, 1> trigger;      ///< Controller trigger.
  S reference;                         ///< r.
};

/// Everything the node needs from the block and the reset parameters.
template <typename S>
constexpr NodeArgs<S> node_args(const S (&w)[kWordCount], const ResetParams& p) {
  return {model_of(w), p.frozen_noise ? node::NoiseAccumulation::kFrozen : node::NoiseAccumulation::kSum,
          law_of(w, p), trigger_of(w, p), w[kReference]};
}

}  // namespace oneshot::app::petc
