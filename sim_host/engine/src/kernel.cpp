/// @file kernel.cpp
/// @brief The discrete-event kernel (see kernel.hpp).
#include "oneshot/engine/kernel.hpp"

#include <stdexcept>

namespace oneshot::engine {

HandlerId Kernel::add_handler(std::string name, Handler handler) {
  if (!handler) throw std::logic_error("kernel: handler '" + name + "' is empty");
  handlers_.push_back(std::move(handler));
  names_.push_back(std::move(name));
  return static_cast<HandlerId>(handlers_.size() - 1);
}

void Kernel::schedule(SimTime at, EventClass cls, HandlerId h, std::uint64_t arg) {
  if (h >= handlers_.size()) throw std::logic_error("kernel: unknown handler id " + std::to_string(h));
  if (at < now_) {
    throw std::logic_error("kernel: '" + names_[h] + "' scheduled at " + std::to_string(at.count()) +
                           " ns, before now (" + std::to_string(now_.count()) + " ns)");
  }
  if (at > kMaxSimTime) {
    throw std::logic_error("kernel: '" + names_[h] + "' scheduled beyond the largest simulated time");
  }
  queue_.push(at, cls, h, arg);
}

std::uint64_t Kernel::run_until(SimTime end) {
  stopped_ = false;
  std::uint64_t run = 0;
  while (!stopped_ && !queue_.empty() && queue_.top().at <= end) {
    const Event e = queue_.pop();
    now_ = e.at;
    current_class_ = e.cls;
    ++run;
    ++events_run_;
    handlers_[e.handler](e.arg);
  }
  return run;
}

}  // namespace oneshot::engine
