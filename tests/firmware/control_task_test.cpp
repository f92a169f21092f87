/// @file control_task_test.cpp
/// @brief The control task on the host port: time crosses 2^32 µs (where a 32-bit host
///        clock wrapped after 71.6 min) and the job still asks for the set-point of the
///        right instant, with the right τ; garbage timer values are refused by range.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "oneshot/app/control_task.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/host/host_board.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot {
namespace {

using K = generated::PlantConstants<double>;
using Structure = generated::PlantStructure;
using Disc = TableDiscretizer<K::Format, Structure, double>;
using Est = HalfKalman<K::Format, Structure, Disc>;
using Ctrl = Controller<K::Format, Structure, Est>;

/// Set-point schedule: code 1000 before the switch instant, 3000 from it on; every query kept.
struct Schedule {
  std::uint64_t switch_us;
  std::vector<std::uint64_t> asked;
  static std::int32_t at(const void* c, std::size_t, std::uint64_t at_us) {
    auto* s = const_cast<Schedule*>(static_cast<const Schedule*>(c));
    s->asked.push_back(at_us);
    return at_us < s->switch_us ? 1000 : 3000;
  }
};

/// The host board of this thread for one test: ADC code 2048, set-point queries to a
/// Schedule switching at `switch_us`.
struct ScheduledBoard {
  explicit ScheduledBoard(std::uint64_t switch_us) : schedule{switch_us, {}}, hb(state(schedule)), scope(hb) {}
  static host::HostBoardState state(Schedule& s) {
    host::HostBoardState b;
    b.adc_codes.assign(1, 2048);
    b.setpoint_at = &Schedule::at;
    b.setpoint_context = &s;
    return b;
  }
  Schedule schedule;
  host::HostBoardState hb;
  const host::ScopedHostBoard scope;
};

TEST(ControlTask, CrossesThe32BitMicrosecondWrapAndTracksTheRightSetpoint) {
  // GIVEN a one-shot task whose jobs run around 2^32 µs, the set-point switching 2 periods after it
  const Disc disc(K::kTable);
  Ctrl ctrl(K::kDesign, Est(K::kDesign, disc, NoiseModel::kExact));
  app::ControlTask<host::HostBoard, Ctrl, app::TaskModel::kOneShot> task(ctrl);
  const std::uint64_t h = static_cast<std::uint64_t>(K::kDesign.period_us);
  const std::uint64_t wrap = std::uint64_t{1} << 32;
  ScheduledBoard board(wrap + 2 * h);
  Schedule& schedule = board.schedule;
  host::HostBoardState& hb = board.hb;
  // WHEN jobs sample 7 ms before each actuation from 5 periods before the wrap to 5 after
  for (std::int64_t k = -5; k <= 5; ++k) {
    const std::uint64_t t_k = wrap + static_cast<std::uint64_t>(k * static_cast<std::int64_t>(h)) + 1234;
    hb.now_us = t_k - 7000;
    hb.next_actuation_us = t_k;
    schedule.asked.clear();
    const Status s = task.run_job();
    // THEN τ is 7 ms, the status exact, and the set-point asked for the true (64-bit) actuation instant
    EXPECT_EQ(task.statistics().last_tau_us, 7000) << "k " << k;
    EXPECT_TRUE(is_exact(s)) << to_string(s);
    ASSERT_EQ(schedule.asked.size(), 1U);
    EXPECT_EQ(schedule.asked[0], t_k) << "k " << k;
    EXPECT_EQ(Schedule::at(&schedule, 0, schedule.asked[0]), t_k < wrap + 2 * h ? 1000 : 3000);
    hb.now_us = t_k;
    task.on_actuation_interrupt();
  }
}

TEST(ControlTask, GarbageTimerValuesAreRefusedByRangeNotOverflowed) {
  // GIVEN a timer compare value 2^40 µs ahead of the clock (a corrupted register)
  const Disc disc(K::kTable);
  Ctrl ctrl(K::kDesign, Est(K::kDesign, disc, NoiseModel::kExact));
  app::ControlTask<host::HostBoard, Ctrl, app::TaskModel::kOneShot> task(ctrl);
  ScheduledBoard board(0);
  host::HostBoardState& hb = board.hb;
  hb.now_us = 1000;
  hb.next_actuation_us = 1000 + (std::uint64_t{1} << 40);
  // WHEN the job runs THEN τ is bounded to kMaxTauUs and the job reports kOutOfRange
  EXPECT_EQ(task.run_job(), Status::kOutOfRange);
  EXPECT_EQ(task.statistics().last_tau_us, kMaxTauUs);
  // AND the other way round
  hb.now_us = std::uint64_t{1} << 41;
  hb.next_actuation_us = 5;
  EXPECT_EQ(task.run_job(), Status::kOutOfRange);
  EXPECT_EQ(task.statistics().last_tau_us, -kMaxTauUs);
}

TEST(ControlTask, FixedPointSaturationReachesTheJobAsAStatus) {
  // GIVEN the fixed-point half filter whose covariance sits at the top of its format
  using KQ = generated::PlantConstants<generated::FixedTag>;
  using FixedDisc = TableDiscretizer<generated::FixedFormat, Structure, BlockFixedStorage>;
  using FixedEst = HalfKalman<generated::FixedFormat, Structure, FixedDisc>;
  using FixedCtrl = Controller<generated::FixedFormat, Structure, FixedEst>;
  using Cov = generated::FixedFormat::Covariance;
  const FixedDisc disc(KQ::kTable);
  FixedCtrl ctrl(KQ::kDesign, FixedEst(KQ::kDesign, disc, NoiseModel::kExact));
  app::ControlTask<host::HostBoard, FixedCtrl, app::TaskModel::kOneShot> task(ctrl);
  ScheduledBoard board(0);
  host::HostBoardState& hb = board.hb;
  hb.now_us = 10'000;
  hb.next_actuation_us = 20'000;
  // A normal job first: exact, no saturation.
  clear_saturation_flag();
  EXPECT_TRUE(is_exact(task.run_job()));
  EXPECT_FALSE(saturation_flag());
  auto p = ctrl.estimator().covariance();
  p(0, 0) = ScalarTraits<Cov>::from_double(Cov::max_value());
  p(1, 1) = p(0, 0);
  ctrl.estimator().reset(ctrl.estimator().prediction(), p, ctrl.applied_input());
  // WHEN the job's prediction Φ P Φᵀ + Q_d saturates
  const Status s = task.run_job();
  // THEN the job reports kOverflow (not exact) and the sticky flag is still raised for the caller
  EXPECT_EQ(s, Status::kOverflow);
  EXPECT_FALSE(is_exact(s));
  EXPECT_TRUE(saturation_flag());
  EXPECT_EQ(task.statistics().faults, 1U);
  clear_saturation_flag();
}

}  // namespace
}  // namespace oneshot
