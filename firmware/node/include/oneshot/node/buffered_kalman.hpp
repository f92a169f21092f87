/// @file buffered_kalman.hpp
/// @brief The buffered intermittent Kalman filter of the over-delay dropping brief (§4):
///        an anchor estimate T_hold periods behind, and a forward re-run to the present.
///
/// Step k (after the arrivals of period k), n = k − T_hold:
///   anchor:  x̂⁻ = Φ x̂(n−1|n−1) + Γ u_{n−1},  P⁻ = Φ P Φᵀ + Q        (kept)
///            x̂(n|n) = x̂⁻ + γ_n K (y_n − C x̂⁻),  P = (I − γ_n K C) P⁻
///   re-run:  from the anchor, for j = n+1 … k: predict with u_{j−1}, correct with y_j
///            iff it is in the buffer now (j ≤ k − 1)                      (scratch)
/// giving x̂(k|Y_k), P_k. At n = 0 the anchor starts from the prior (x̂₀, P₀) without a
/// prediction; while n < 0 only the re-run runs (from the prior). Cost per step: T_hold + 1
/// predictions, at most T_hold corrections; memory: T_hold outputs + flags (ThresholdBuffer),
/// T_hold + 1 inputs, one anchor. T_hold = 1 is Sinopoli's intermittent filter.
/// Predictions and corrections are the core's (predict_state, predict_covariance with the
/// constant per-step Q, correct() in the symmetric form).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/kalman_correction.hpp"
#include "oneshot/node/threshold_buffer.hpp"
#include "oneshot/one_shot_predictor.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/scalar_traits.hpp"

namespace oneshot::node {

/// The model a BufferedKalman runs on (per step).
template <typename Fmt, std::size_t N, std::size_t M, std::size_t P>
struct BufferedKalmanModel {
  Discretization<Fmt, N, M> step;                    ///< Φ, Γ of one period (qd unused).
  Matrix<typename Fmt::Covariance, N, N> q;          ///< Q per step.
  Matrix<typename Fmt::Transition, P, N> c;          ///< C.
  Matrix<typename Fmt::Covariance, P, P> r;          ///< R.
};

/// Anchor + re-run filter with a threshold buffer of kHold periods.
template <typename Fmt, typename Structure, std::size_t kHold>
class BufferedKalman {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static constexpr std::size_t kP = Structure::kOutputs;
  using StateVec = Vector<typename Fmt::State, kN>;
  using OutputVec = Vector<typename Fmt::State, kP>;
  using InputVec = Vector<typename Fmt::Input, kM>;
  using Cov = Matrix<typename Fmt::Covariance, kN, kN>;
  using Gain = Matrix<typename Fmt::KalmanGain, kN, kP>;
  using Model = BufferedKalmanModel<Fmt, kN, kM, kP>;
  using Buffer = ThresholdBuffer<OutputVec, kHold>;
  // Near the critical arrival probability P reaches 1e5–1e9: a fixed format would saturate.
  static_assert(kIsFloating<typename Fmt::Covariance>, "the buffered filter needs a floating covariance format");

  /// Filter over `model` (must outlive it), prior (x0, p0) of x_0, before step 0.
  constexpr BufferedKalman(const Model& model, const StateVec& x0, const Cov& p0) : model_(&model) { reset(x0, p0); }

  /// Restarts before step 0 with the prior (x0, p0).
  constexpr void reset(const StateVec& x0, const Cov& p0) {
    buffer_ = Buffer(0);
    ax_ = x0;
    ap_ = p0;
    anchor_index_ = 0;
    anchor_posterior_ = false;
    passed_hold_ = false;
    head_ = 0;
    x_ = x0;
    p_ = p0;
    step_ = 0;
    last_gamma_ = false;
    status_ = Status::kOk;
  }

  /// A packet arrived (stamp j, value y): see ThresholdBuffer::receive.
  [[nodiscard]] constexpr ArrivalVerdict receive(std::uint32_t stamp, const OutputVec& y) { return buffer_.receive(stamp, y); }

  /// Step k: anchor to n = k − T_hold, re-run to k. Returns the first failure of the step.
  [[nodiscard]] constexpr Status step() {
    const std::uint32_t k = step_;
    Status st = Status::kOk;
    corrections_ = 0;
    // n = k − T_hold ≥ 0 (counting steps from 0; k itself may have wrapped long after).
    const bool anchor_moves = passed_hold_ || k >= kHold;
    OutputVec y{};
    last_gamma_ = buffer_.advance(anchor_moves, y);
    if (anchor_moves) {
      passed_hold_ = true;
      if (anchor_posterior_) {  // x̂(n−1|n−1) → x̂(n|n−1)
        predict(ax_, ap_, input_back(kHold + 1));  // u_{n−1}
        ++anchor_index_;
      }
      if (last_gamma_) st = first_failure(st, correct_with(ax_, ap_, y));
      anchor_posterior_ = true;
    }
    // Re-run from the anchor to k.
    x_ = ax_;
    p_ = ap_;
    std::uint32_t j = anchor_index_;
    bool posterior = anchor_posterior_;
    for (;;) {
      OutputVec yj{};
      if (!posterior && j != k && buffer_.holds(j, yj)) st = first_failure(st, correct_with(x_, p_, yj));
      if (j == k) break;
      predict(x_, p_, input_back(k - j));  // u_j
      ++j;
      posterior = false;
    }
    ++step_;
    head_ = (head_ + 1) % kInputSlots;
    status_ = first_failure(status_, st);
    return st;
  }

  /// The input applied in the current step (k − 1 after step()): u_{k−1}.
  constexpr void set_applied_input(const InputVec& u) { inputs_[(head_ + kInputSlots - 1) % kInputSlots] = u; }

  /// x̂(k|Y_k) of the last step.
  constexpr const StateVec& estimate() const { return x_; }
  /// P_k of the last step.
  constexpr const Cov& covariance() const { return p_; }
  /// The anchor x̂(n|n) (the prior of x_0 before the first anchor step).
  constexpr const StateVec& anchor() const { return ax_; }
  /// The anchor's covariance.
  constexpr const Cov& anchor_covariance() const { return ap_; }
  /// The anchor's index n.
  constexpr std::uint32_t anchor_index() const { return anchor_index_; }
  /// Whether the anchor has been corrected (or skipped) at least once (n ≥ 0).
  constexpr bool anchor_started() const { return anchor_posterior_; }
  /// γ_n of the last step (false while n < 0).
  constexpr bool last_gamma() const { return last_gamma_; }
  /// Corrections the last step made (anchor and re-run; at most T_hold).
  constexpr std::uint32_t last_corrections() const { return corrections_; }
  /// Steps taken (the next step's k).
  constexpr std::uint32_t steps() const { return step_; }
  /// First failure since reset.
  [[nodiscard]] constexpr Status status() const { return status_; }
  /// The buffer (counters).
  constexpr const Buffer& buffer() const { return buffer_; }

 private:
  static constexpr std::size_t kInputSlots = kHold + 1;

  /// u_{k−d} during step k (1 ≤ d ≤ T_hold + 1); head_ is u_k's slot, so the ring never
  /// depends on the step counter's wrap.
  constexpr const InputVec& input_back(std::uint32_t d) const { return inputs_[(head_ + kInputSlots - d) % kInputSlots]; }

  constexpr void predict(StateVec& x, Cov& p, const InputVec& u) const {
    x = predict_state<Fmt, Structure>(model_->step, x, u);
    p = predict_covariance<Fmt, Structure>(model_->step, p, NoiseModel::kConstant, model_->q);
  }

  [[nodiscard]] constexpr Status correct_with(StateVec& x, Cov& p, const OutputVec& y) {
    ++corrections_;
    return correct<Fmt, Structure, CovarianceUpdate::kSymmetric>(x, p, y, model_->c, model_->r, gain_);
  }

  const Model* model_;
  Buffer buffer_{};
  InputVec inputs_[kInputSlots]{};
  StateVec ax_{};
  Cov ap_{};
  std::uint32_t anchor_index_ = 0;
  bool anchor_posterior_ = false;
  bool passed_hold_ = false;
  StateVec x_{};
  Cov p_{};
  Gain gain_{};
  std::uint32_t step_ = 0;
  std::size_t head_ = 0;
  bool last_gamma_ = false;
  std::uint32_t corrections_ = 0;
  Status status_ = Status::kOk;
};

}  // namespace oneshot::node
