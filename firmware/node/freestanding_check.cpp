/// @file freestanding_check.cpp
/// @brief Compiles the node logic with -ffreestanding -fno-exceptions -fno-rtti against a
///        minimal network port (float and double; every trigger rule, both modes).
#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/node/packet_buffer.hpp"
#include "oneshot/node/petc_controller.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"

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
  bool compute(const oneshot::node::Message<oneshot::node::VectorPayload<S, 1>>& m, bool, oneshot::McuInstant,
               oneshot::Vector<S, 1>& u) {
    u[0] = -(gain * m.payload.value[0]);
    return true;
  }
};

template <typename S>
void exercise() {
  using namespace oneshot::node;
  using V = oneshot::Vector<S, 1>;
  V delta;
  delta[0] = oneshot::ScalarTraits<S>::from_ratio(1, 100);
  SensorNode<NullBoard, SendOnDeltaTrigger<S, 1>, S, 1> sod(2, SendOnDeltaTrigger<S, 1>(delta, 5));
  SensorNode<NullBoard, PeriodicTrigger<S, 1>, S, 1> periodic(2, PeriodicTrigger<S, 1>(1));
  SensorNode<NullBoard, MtmTrigger<S, 1>, S, 1> mtm(2, MtmTrigger<S, 1>(delta[0], delta[0], 50, 3));
  ControllerNode<NullBoard, ProportionalLaw<S>, S, 1, 1> ctrl(3, ControllerMode::kOnArrival,
                                                            ProportionalLaw<S>{oneshot::ScalarTraits<S>::one()});
  ActuatorNode<NullBoard, S, 1> act(ActuatorMode::kOnTimer, V{});
  const oneshot::McuInstant now(7);
  sod.on_sample(0, now, delta);
  periodic.on_sample(0, now, delta);
  mtm.on_sample(0, now, delta);
  ctrl.on_receive(now);
  ctrl.on_timer(now);
  act.on_receive();
  act.on_timer(0);
  V u;
  static_cast<void>(act.take_output(u));

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
  static_cast<void>(buffer.accept(0, petc.packet()));
  static_cast<void>(buffer.value(3));
}

}  // namespace

/// Referenced so the instantiations are compiled.
void oneshot_node_freestanding_check() {
  exercise<float>();
  exercise<double>();
}
