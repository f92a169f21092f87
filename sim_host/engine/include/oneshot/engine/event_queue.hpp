/// @file event_queue.hpp
/// @brief The engine's pending events in a deterministic total order.
///
/// Events are ordered by (time, class, insertion sequence): at one instant the classes
/// run in the physical order of EventClass (a discrete plant steps first, then reference
/// changes, actuation, sampling, deliveries, computations, input latches, bus arbitration,
/// recording, end),
/// and events of one class run in the order they were scheduled. The sequence number is
/// global to the queue, so the order never depends on the heap's internals or on the
/// thread: the same run gives the same order every time.
#pragma once

#include <cstdint>
#include <queue>
#include <vector>

#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// Order of simultaneous events (lower runs first).
enum class EventClass : std::uint8_t {
  kPlantStep = 0,    ///< A discrete plant steps x_k → x_{k+1} at the period boundary.
  kEnvironment = 1,  ///< Reference, set-point or disturbance changes.
  kActuation = 2,    ///< An actuator applies an input (timer interrupt, job output).
  kSample = 3,       ///< A sensor samples (and a job that samples as it starts).
  kDelivery = 4,     ///< A message reaches its destination.
  kCompute = 5,      ///< A computation runs (controller on its timer, job completion).
  kLatch = 6,        ///< A discrete plant latches the input in force for its next step.
  kBus = 7,          ///< A bus arbitrates among the frames queued up to this instant.
  kRecord = 8,       ///< Monitors and recorders observe the instant.
  kEnd = 9,          ///< End of the run.
};

/// Index of a registered event handler.
using HandlerId = std::uint32_t;

/// One pending event.
struct Event {
  SimTime at{0};                            ///< When.
  EventClass cls = EventClass::kCompute;    ///< Class among simultaneous events.
  std::uint64_t seq = 0;                    ///< Insertion sequence (tie-break).
  HandlerId handler = 0;                    ///< Which handler runs it.
  std::uint64_t arg = 0;                    ///< Argument handed to the handler.
};

/// a runs before b.
constexpr bool runs_before(const Event& a, const Event& b) {
  if (a.at != b.at) return a.at < b.at;
  if (a.cls != b.cls) return a.cls < b.cls;
  return a.seq < b.seq;
}

/// Min-heap of events in (time, class, sequence) order.
class EventQueue {
 public:
  /// Adds an event; its sequence number is assigned here.
  void push(SimTime at, EventClass cls, HandlerId handler, std::uint64_t arg) {
    heap_.push(Event{at, cls, next_seq_++, handler, arg});
  }
  /// True when nothing is pending.
  bool empty() const { return heap_.empty(); }
  /// Number of pending events.
  std::size_t size() const { return heap_.size(); }
  /// The next event (queue not empty).
  const Event& top() const { return heap_.top(); }
  /// Removes and returns the next event (queue not empty).
  Event pop() {
    Event e = heap_.top();
    heap_.pop();
    return e;
  }

 private:
  struct Later {
    bool operator()(const Event& a, const Event& b) const { return runs_before(b, a); }
  };
  std::priority_queue<Event, std::vector<Event>, Later> heap_;
  std::uint64_t next_seq_ = 0;
};

}  // namespace oneshot::engine
