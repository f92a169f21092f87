/// @file kernel.hpp
/// @brief The discrete-event kernel: simulated clock, event queue, handlers, random streams.
///
/// A run registers its handlers once (add_handler), schedules the first events, and calls
/// run_until(). Each event carries a handler id and a 64-bit argument (a period index, a
/// message slot, a node id …), so scheduling allocates nothing. Handlers may schedule
/// further events at the current instant or later; an event scheduled for the current
/// instant in a class that has already run at this instant runs right after the current
/// handler (never before it). Time never goes back: scheduling in the past is an error.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "oneshot/engine/event_queue.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine {


/// The event loop of one run (single-threaded; one kernel per run).
class Kernel {
 public:
  /// Handler signature: called with the event's argument.
  using Handler = std::function<void(std::uint64_t arg)>;

  /// Kernel at t = 0 for experiment seed `seed`.
  explicit Kernel(std::uint64_t seed) : seed_(seed) {}
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  /// Registers a handler; `name` appears in error messages.
  HandlerId add_handler(std::string name, Handler handler);

  /// Schedules handler `h` with `arg` at `at` (≥ now, ≤ kMaxSimTime) in class `cls`.
  void schedule(SimTime at, EventClass cls, HandlerId h, std::uint64_t arg = 0);
  /// Schedules `delay` (≥ 0) after now.
  void schedule_in(Duration delay, EventClass cls, HandlerId h, std::uint64_t arg = 0) {
    schedule(now_ + delay, cls, h, arg);
  }

  /// Runs events in order while the next one is at or before `end`; returns the number run.
  /// Afterwards now() is the time of the last event run (or unchanged).
  std::uint64_t run_until(SimTime end);
  /// Makes run_until() return after the current handler.
  void stop() { stopped_ = true; }

  /// Current simulated time.
  SimTime now() const { return now_; }
  /// Class of the event being run (meaningful inside a handler).
  EventClass current_class() const { return current_class_; }
  /// Events run so far.
  std::uint64_t events_run() const { return events_run_; }
  /// Events pending.
  std::size_t pending() const { return queue_.size(); }
  /// The experiment seed.
  std::uint64_t seed() const { return seed_; }
  /// An independent stream of this run's seed (see random_stream.hpp).
  RandomStream stream(std::string_view name) const { return RandomStream(seed_, name); }

 private:
  std::uint64_t seed_;
  SimTime now_{0};
  EventClass current_class_ = EventClass::kEnvironment;
  EventQueue queue_;
  std::vector<Handler> handlers_;
  std::vector<std::string> names_;
  std::uint64_t events_run_ = 0;
  bool stopped_ = false;
};

}  // namespace oneshot::engine
