/// @file control_drivers.hpp
/// @brief The seed-000 control task as the board loop drives it: in-process through the
///        host port (LocalDriver), or in the emulated MCU behind the PIL link (RemoteDriver).
///
/// Both implement BoardDriver: reset(initial codes, P0 scale), actuation(board) for the
/// timer interrupt, job(board) for one control job, statistics() and saturated(); the
/// board loop (board_loop.hpp) calls them from its engine events.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "oneshot/app/control_task.hpp"
#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/host/host_board.hpp"
#include "approach.hpp"
#include "oneshot/sim/pil_link.hpp"

namespace oneshot::sim {

template <typename T, typename = void>
struct HasGain : std::false_type {};
template <typename T>
struct HasGain<T, std::void_t<decltype(std::declval<const T&>().gain())>> : std::true_type {};

template <typename S>
double to_double(S v) {
  return ScalarTraits<S>::to_double(v);
}

/// What the loop reads back from a job.
template <std::size_t N>
struct JobReport {
  std::int32_t tau_us = 0;
  double estimate[N] = {};
  double gain0 = 0;
  double u_applied = 0;
};

/// What the board loop drives, for N states and M inputs.
///
/// Virtual on purpose: this is the host harness around the job, not the control path (the
/// job itself stays the statically typed Controller). One board loop per (n, m, p, task
/// model) instead of one per estimator × discretizer × number format keeps the simulator's
/// build time bounded.
template <std::size_t N, std::size_t M>
class BoardDriver {
 public:
  virtual ~BoardDriver() = default;
  /// Starts a run: the PWM codes in force at power-on and the factor on P0.
  virtual void reset(const std::int32_t (&codes)[M], double p0_scale) = 0;
  /// The timer interrupt at an actuation instant.
  virtual void actuation(host::HostBoardState& board) = 0;
  /// One control job on the board's current ADC codes.
  virtual JobReport<N> job(host::HostBoardState& board) = 0;
  /// Jobs, overruns and faults so far.
  virtual const app::TaskStatistics& statistics() const = 0;
  /// True once any value saturated.
  virtual bool saturated() const = 0;
};

/// The firmware's control task run in-process through the host port.
template <typename Ctrl, app::TaskModel kModel>
class LocalDriver final : public BoardDriver<Ctrl::kN, Ctrl::kM> {
 public:
  static constexpr std::size_t kN = Ctrl::kN;
  static constexpr std::size_t kM = Ctrl::kM;
  explicit LocalDriver(Ctrl& ctrl) : ctrl_(&ctrl), task_(ctrl) {}
  void reset(const std::int32_t (&codes)[kM], double p0_scale) override {
    typename Ctrl::InputVec u0;
    for (std::size_t j = 0; j < kM; ++j) u0[j] = input_of_code(ctrl_->design().actuator, j, codes[j]);
    // P0 scaled entry by entry in double (a fixed covariance format cannot hold the factor).
    auto p0 = ctrl_->design().p0;
    using CovScalar = typename Ctrl::CovScalar;
    for (std::size_t k = 0; k < p0.kSize; ++k) {
      p0[k] = ScalarTraits<CovScalar>::from_double(ScalarTraits<CovScalar>::to_double(p0[k]) * p0_scale);
    }
    clear_saturation_flag();
    ctrl_->estimator().reset(typename Ctrl::StateVec{}, p0, u0);
    task_.reset();
  }
  void actuation(host::HostBoardState&) override { task_.on_actuation_interrupt(); }
  JobReport<kN> job(host::HostBoardState&) override {
    (void)task_.run_job();  // the task keeps the status in its statistics (statistics())
    JobReport<kN> r;
    r.tau_us = task_.statistics().last_tau_us;
    for (std::size_t i = 0; i < kN; ++i) r.estimate[i] = to_double(ctrl_->estimator().prediction()[i]);
    if constexpr (HasGain<typename Ctrl::EstimatorType>::value) r.gain0 = to_double(ctrl_->estimator().gain()[0]);
    r.u_applied = to_double(ctrl_->applied_input()[0]);
    return r;
  }
  const app::TaskStatistics& statistics() const override { return task_.statistics(); }
  bool saturated() const override { return saturation_flag(); }

 private:
  Ctrl* ctrl_;
  app::ControlTask<host::HostBoard, Ctrl, kModel> task_;
};

/// Decodes a raw 32-bit value of the firmware (IEEE bits, or a fixed mantissa) in format T.
template <typename T>
double decode_raw(std::uint32_t raw) {
  if constexpr (kIsFloating<T>) {
    static_assert(sizeof(T) == 4, "the firmware reports single precision");
    float f = 0;
    std::memcpy(&f, &raw, 4);
    return static_cast<double>(f);
  } else {
    using Storage = typename T::StorageType;
    return ScalarTraits<T>::to_double(T::from_raw(static_cast<Storage>(static_cast<std::int32_t>(raw))));
  }
}

/// The firmware's control task run in QEMU, behind the PIL link.
template <typename Fmt, std::size_t N, std::size_t M, std::size_t P, app::TaskModel kModel>
class RemoteDriver final : public BoardDriver<N, M> {
 public:
  RemoteDriver(PilLink& link, Approach approach, NoiseModel noise) : link_(&link), approach_(approach), noise_(noise) {}
  void reset(const std::int32_t (&codes)[M], double p0_scale) override {
    if (p0_scale != 1.0) throw std::invalid_argument("PIL runs start from the design's initial covariance (p0 scale 1)");
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(static_cast<std::uint32_t>(approach_), 1);
    w.u(noise_ == NoiseModel::kExact ? 1U : 0U, 1);
    for (std::size_t j = 0; j < M; ++j) w.u(static_cast<std::uint32_t>(codes[j]), 2);
    link_->request(app::pil::Type::kConfig, f);
    stats_ = app::TaskStatistics{};
    saturated_ = false;
  }
  void actuation(host::HostBoardState& b) override {
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(static_cast<std::uint32_t>(b.now_us), 4);  // the MCU's 32-bit timer: wraps, wrap-safe there
    const app::pil::Frame r = link_->request(app::pil::Type::kTick, f);
    app::pil::Reader in(r);
    const std::size_t writes = read_writes(in, b);
    if (kModel == app::TaskModel::kOneShot && writes == 0 && stats_.jobs > 0) ++stats_.overruns;
  }
  JobReport<N> job(host::HostBoardState& b) override {
    const std::uint64_t t_apply = kModel == app::TaskModel::kOneShot ? b.next_actuation_us : b.now_us;
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(static_cast<std::uint32_t>(b.now_us), 4);  // the MCU's 32-bit timer: wraps, wrap-safe there
    w.u(static_cast<std::uint32_t>(b.next_actuation_us), 4);
    for (std::size_t o = 0; o < P; ++o) w.s(b.adc_codes[o], 2);
    for (std::size_t o = 0; o < P; ++o) w.s(b.setpoint_at(b.setpoint_context, o, t_apply), 2);
    const app::pil::Frame r = link_->request(app::pil::Type::kSample, f);
    app::pil::Reader in(r);
    const auto status = static_cast<Status>(in.u(1));
    JobReport<N> rep;
    rep.tau_us = in.s(4);
    if (in.u(1) != 0U) saturated_ = true;
    read_writes(in, b);
    double u[M] = {};
    for (std::size_t j = 0; j < M; ++j) u[j] = decode_raw<typename Fmt::Input>(in.u(4));
    rep.u_applied = u[0];
    for (std::size_t i = 0; i < N; ++i) rep.estimate[i] = decode_raw<typename Fmt::State>(in.u(4));
    rep.gain0 = decode_raw<typename Fmt::KalmanGain>(in.u(4));
    if (in.bad()) throw PilError("PIL: short job reply");
    ++stats_.jobs;
    stats_.last_tau_us = rep.tau_us;
    stats_.last_status = status;
    if (!is_exact(status)) ++stats_.faults;
    return rep;
  }
  const app::TaskStatistics& statistics() const override { return stats_; }
  bool saturated() const override { return saturated_; }

 private:
  static std::size_t read_writes(app::pil::Reader& in, host::HostBoardState& b) {
    const std::size_t n = in.u(1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t ch = in.u(1);
      const auto code = static_cast<std::int32_t>(in.u(2));
      b.pwm_writes.push_back(host::PwmWrite{ch, code, b.now_us});
    }
    return n;
  }

  PilLink* link_;
  Approach approach_;
  NoiseModel noise_;
  app::TaskStatistics stats_{};
  bool saturated_ = false;
};

}  // namespace oneshot::sim
