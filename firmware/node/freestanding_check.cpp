/// @file freestanding_check.cpp
/// @brief Compiles the node logic with -ffreestanding -fno-exceptions -fno-rtti against a
///        minimal network port (float and double; every trigger rule, both modes).
#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/buffered_kalman.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/dropout_detector.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/node/packet_buffer.hpp"
#include "oneshot/node/petc_controller.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/node/sampling_sync_laws.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/plant_structure.hpp"

namespace {

struct NullBoard {
  struct Net {
    static std::uint8_t address() { return 1; }
    static bool send(std::uint8_t, const std::uint8_t*, std::size_t) { return true; }
    static std::size_t receive(std::uint8_t&, std::uint8_t*, std::size_t) { return 0; }
  };
};
static_assert(oneshot::hal::kHasNetwork<NullBoard>);

template <typename S>
struct ProportionalLaw {
  S gain;
  oneshot::node::LawResult compute(const oneshot::node::Message<oneshot::node::VectorPayload<S, 1>>& m, bool,
                                    oneshot::McuInstant, oneshot::Vector<S, 1>& u) {
    u[0] = -(gain * m.payload.value[0]);
    return oneshot::node::LawResult::kSend;
  }
};

/// A small threshold δ = 0.01 (1-vector) the exercises below share.
template <typename S>
oneshot::Vector<S, 1> small_delta() {
  oneshot::Vector<S, 1> delta;
  delta[0] = oneshot::ScalarTraits<S>::from_ratio(1, 100);
  return delta;
}

template <typename S>
void exercise() {
  using namespace oneshot::node;
  using V = oneshot::Vector<S, 1>;
  const V delta = small_delta<S>();
  SensorNode<NullBoard, SendOnDeltaTrigger<S, 1>, S, 1> sod(2, SendOnDeltaTrigger<S, 1>(delta, 5));
  SensorNode<NullBoard, PeriodicTrigger<S, 1>, S, 1> periodic(2, PeriodicTrigger<S, 1>(1));
  SensorNode<NullBoard, MtmTrigger<S, 1>, S, 1> mtm(2, MtmTrigger<S, 1>(delta[0], delta[0], 50, 3));
  ControllerNode<NullBoard, ProportionalLaw<S>, S, 1, 1> ctrl(3, ControllerMode::kOnArrival,
                                                            ProportionalLaw<S>{oneshot::ScalarTraits<S>::one()});
  ActuatorNode<NullBoard, S, 1> act(ActuatorMode::kOnTimer, V{});
  ctrl.expect_source(1);
  ctrl.set_measurement_range(V{}, V{});
  ctrl.set_sequence_window(64, 3);
  act.set_sequence_window(64, 3);
  const oneshot::McuInstant now(7);
  sod.on_sample(0, now, delta);
  periodic.on_sample(0, now, delta);
  mtm.on_sample(0, now, delta);
  ctrl.on_receive(now);
  ctrl.on_timer(now);
  act.on_receive();
  act.on_timer(0);
  static_cast<void>(ctrl.receive_status() == act.receive_status());
  V u;
  static_cast<void>(act.take_output(u));
  // The buffered intermittent filter (threshold buffer, anchor, re-run), 3 states, T_hold = 4.
  using Fmt = oneshot::UniformFormat<S>;
  using Structure = oneshot::DenseStructure<3, 1, 1>;
  using Filter = BufferedKalman<Fmt, Structure, 4>;
  typename Filter::Model model{};
  Filter filter(model, typename Filter::StateVec{}, typename Filter::Cov{});
  static_cast<void>(filter.receive(0, typename Filter::OutputVec{}));
  static_cast<void>(filter.step());
  filter.set_applied_input(typename Filter::InputVec{});
}

/// The actuation-synchronized nodes and the baseline laws of the networked-actuation study.
template <typename S>
void exercise_sync() {
  using namespace oneshot;
  using namespace oneshot::node;
  using Fmt = UniformFormat<S>;
  using Structure = DenseStructure<2, 1, 2>;
  using Disc = GenericDiscretizer<Fmt, 2, 1>;
  using Ref = SquareWaveReference<S, 2, 1>;
  static const typename Disc::Model model{};
  static const Disc disc(model);
  static const ControllerDesign<Fmt, 2, 1, 2> design{};
  const Ref ref(ScalarTraits<S>::one(), 20, Vector<S, 2>{}, Vector<S, 1>{});
  const Vector<S, 1> lo{};
  const Vector<S, 1> hi{};
  const McuInstant now(7);
  SyncActuatorNode<NullBoard, S, 1> act(1, lo);
  act.expect_source(3);
  act.set_command_range(lo, hi);
  act.start(now);
  act.on_receive();
  act.on_timer(1, now);
  SyncSensorNode<NullBoard, S, 2, 1> sensor(2, 5000);
  sensor.expect_source(1);
  sensor.set_echo_range(lo, hi);
  sensor.set_stamp_window(200000);
  sensor.set_sequence_window(64, 3);
  McuInstant at;
  if (sensor.on_receive(now, at)) static_cast<void>(sensor.on_sample(at, Vector<S, 2>{}) == ReportResult::kSent);
  SyncControllerNode<NullBoard, HalfKalmanEstimator<Fmt, Structure, Disc>, Ref, S, 2, 2, 1> ak(
      3, design.l, lo, hi, HalfKalmanEstimator<Fmt, Structure, Disc>(design, disc, NoiseModel::kExact), ref);
  ak.expect_source(2);
  ak.set_measurement_range(Vector<S, 2>{}, Vector<S, 2>{});
  ak.check_echo_range();
  ak.set_tau_range(0, 50000);
  ak.on_receive(now);
  SyncControllerNode<NullBoard, SampledStatePredictor<Fmt, Structure, Disc>, Ref, S, 2, 2, 1> a(
      3, design.l, lo, hi, SampledStatePredictor<Fmt, Structure, Disc>(disc), ref);
  a.on_receive(now);
  ControllerNode<NullBoard, StateFeedbackLaw<S, 2, 1, Ref>, S, 2, 1> s(
      3, ControllerMode::kOnArrival, StateFeedbackLaw<S, 2, 1, Ref>{design.l, lo, hi, ref});
  s.on_receive(now);
  ControllerNode<NullBoard, PeriodicKalmanLaw<Fmt, Structure, Ref>, S, 2, 1> sk(
      3, ControllerMode::kOnArrival, PeriodicKalmanLaw<Fmt, Structure, Ref>(design, NoiseModel::kConstant, lo, hi, ref));
  sk.on_receive(now);
  ControllerNode<NullBoard, DelayCompensatedLaw<S, 2, 1, Ref>, S, 2, 1> sp(
      3, ControllerMode::kOnArrival, DelayCompensatedLaw<S, 2, 1, Ref>{design.l, Matrix<S, 1, 1>{}, lo, hi, ref});
  sp.on_receive(now);
}

/// The send-on-delta receiver (dropout detector, held values) and its estimator.
template <typename S>
void exercise_sod() {
  using namespace oneshot::node;
  using V = oneshot::Vector<S, 1>;
  const V delta = small_delta<S>();
  // Receiver and estimator of send-on-delta nodes (two nodes, two states).
  using V2 = oneshot::Vector<S, 2>;
  using M2 = oneshot::Matrix<S, 2, 2>;
  const std::uint32_t n_t[2] = {0, 100};
  V2 dy;
  dy[0] = delta[0];
  dy[1] = delta[0];
  HeldMeasurementReceiver<S, 2> rx(dy, dy, n_t, SilencePolicy::kHeld);
  static_cast<void>(rx.on_packet(0, 0, delta[0]) == FrameStatus::kOk);
  M2 eye;
  eye(0, 0) = oneshot::ScalarTraits<S>::one();
  eye(1, 1) = oneshot::ScalarTraits<S>::one();
  HeldMeasurementEstimator<S, 2, 1, 2> est(eye, oneshot::Matrix<S, 2, 1>{}, eye, eye);
  est.reset(V2{}, eye);
  static_cast<void>(est.predict(V{}));
  for (std::size_t i = 0; i < 2; ++i) {
    const HeldMeasurement<S> m = rx.measurement(i, 1);
    if (m.present) static_cast<void>(est.correct(i, m.z, m.r_bar));
  }
}

/// NUMRE, the interlaced controller, the disturbance estimates and the packet buffer.
template <typename S>
void exercise_petc() {
  using namespace oneshot::node;
  const oneshot::Vector<S, 1> delta = small_delta<S>();
  // PETC: NUMRE, interlaced law, both disturbance estimates, packet buffer.
  using Law = InterlacedController<S, 1, 2>;
  InterlacedConfig<S, 1, 2> lc{};
  lc.ratio = 2;
  NumreModel<S, 4> model{};
  const MtmTrigger<S, 1> trig(delta[0], delta[0], 8, 0);
  PetcController<S, 4, 8, Law, ModelDisturbance<S>> petc(model, NoiseAccumulation::kSum, Law(lc), ModelDisturbance<S>{},
                                                         trig, delta[0]);
  static_cast<void>(petc.on_arrival(0, delta[0]));
  DisturbanceObserverConfig<S, 2, 4> oc{};
  using Dob = DisturbanceObserver<S, 2, 4>;
  PetcController<S, 4, 8, Law, Dob> petc_dob(model, NoiseAccumulation::kFrozen, Law(lc), Dob(oc), trig, delta[0]);
  static_cast<void>(petc_dob.on_arrival(0, delta[0]));
  PacketBuffer<S, 8> buffer;
  static_cast<void>(buffer.accept(0, petc.packet()) == FrameStatus::kOk);
  static_cast<void>(buffer.value(3));
}

}  // namespace

/// Referenced so the instantiations are compiled.
void oneshot_node_freestanding_check() {
  exercise<float>();
  exercise<double>();
  exercise_sync<float>();
  exercise_sync<double>();
  exercise_sod<float>();
  exercise_sod<double>();
  exercise_petc<float>();
  exercise_petc<double>();
}
