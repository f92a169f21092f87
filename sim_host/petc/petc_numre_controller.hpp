/// @file petc_numre_controller.hpp
/// @brief The NUMRE controller node (node::PetcController) wrapped for the petc run
///        (petc_sim.cpp), beside the controller of the cases without NUMRE
///        (petc_hold_controller.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "oneshot/node/petc_controller.hpp"
#include "petc_hold_controller.hpp"
#include "petc_sim.hpp"

namespace oneshot::sim::petc {

/// `d` as an R×C matrix; std::invalid_argument naming `what` when its size differs.
template <std::size_t R, std::size_t C>
inline Matrix<double, R, C> model_matrix(const DenseMatrix& d, const char* what) {
  if (d.rows != R || d.cols != C)
    throw std::invalid_argument(std::string("petc: ") + what + " is " + std::to_string(d.rows) + "x" +
                                std::to_string(d.cols) + ", the study is compiled for " + std::to_string(R) + "x" +
                                std::to_string(C));
  Matrix<double, R, C> m;
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j) m(i, j) = d(i, j);
  return m;
}

/// The estimator model `e` as the NUMRE node's model of N states.
template <std::size_t N>
node::NumreModel<double, N> numre_model(const EstimatorModel& e) {
  node::NumreModel<double, N> m;
  m.a = model_matrix<N, N>(e.a, "A");
  m.b = model_matrix<N, 1>(e.b, "B");
  m.b_w = model_matrix<N, 1>(e.b_w, "B_w");
  m.c = model_matrix<1, N>(e.c, "C");
  m.c_bar = model_matrix<1, N>(e.c_bar, "C_bar");
  m.w = e.w;
  m.v = e.v;
  return m;
}

/// NUMRE controller node wrapped for the loop, compiled for the model's `Structure` (the
/// augmented model: the M4F image's HddStructure, so the multiply-adds are the image's).
template <std::size_t N, typename Observer, typename Structure = node::DenseModelStructure<N>>
class NumreController {
 public:
  /// The wrapped node.
  using Node = node::PetcController<double, N, kHorizon, Law, Observer, Structure>;
  /// The node on model `m` (refused when it does not fit Structure), noise accumulation frozen
  /// or summed, law, disturbance observer, controller trigger and reference r.
  NumreController(const EstimatorModel& m, bool frozen, const Law& law, const Observer& obs, const Trigger& trig,
                  double r)
      : node_(std::make_unique<Node>(fitting(numre_model<N>(m)), frozen ? node::NoiseAccumulation::kFrozen
                                                                        : node::NoiseAccumulation::kSum,
                                     law, obs, trig, r)) {}
  /// A deep copy (the power-on node kept for a restart).
  NumreController(const NumreController& o) : node_(std::make_unique<Node>(*o.node_)), last_macs_(o.last_macs_) {}
  NumreController& operator=(const NumreController&) = delete;
  /// Restart: the power-on node `p` again (its estimator resets so far are kept in the count).
  void restart_as(const NumreController& p) {
    resets_ += node_->statistics().estimator_resets;
    *node_ = *p.node_;
  }
  /// Estimates that turned non-finite (reset by the node), restarts included.
  std::uint32_t estimator_resets() const { return resets_ + node_->statistics().estimator_resets; }
  /// y_k arrived: the node's estimate, law and trigger; what it sends (last_macs() its cost).
  node::SendCause arrive(std::uint32_t k, double y) {
    const std::uint64_t before = node_->macs();
    const node::SendCause c = node_->on_arrival(k, y);
    last_macs_ = node_->macs() - before;
    return c;
  }
  /// The last packet of future inputs (H + 1 entries).
  const double* packet() const { return node_->packet(); }
  /// Multiply-adds so far.
  std::uint64_t macs() const { return node_->macs(); }
  /// Multiply-adds of the last arrival.
  std::uint64_t last_macs() const { return last_macs_; }
  /// Periods since the previous arrival (the estimator's last multiplicity).
  std::uint32_t multiplicity() const { return node_->estimator().last_multiplicity(); }
  /// The disturbance estimate at step k.
  double d_hat(std::uint32_t k) const { return node_->disturbance_estimate(k); }
  /// Appends the estimate to the trace.
  void record_state(RunTrace& t) const {
    const auto& x = node_->estimator().state();
    t.x_hat.emplace_back(x.data(), x.data() + N);
  }

 private:
  std::unique_ptr<Node> node_;
  std::uint64_t last_macs_ = 0;
  std::uint32_t resets_ = 0;

  /// The model, refused when it has a nonzero outside Structure.
  static const node::NumreModel<double, N>& fitting(const node::NumreModel<double, N>& m) {
    if (!Node::fits(m)) throw std::invalid_argument("petc: the NUMRE model has a nonzero outside its compiled structure");
    return m;
  }
};

}  // namespace oneshot::sim::petc
