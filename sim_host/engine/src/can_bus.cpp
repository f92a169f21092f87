/// @file can_bus.cpp
/// @brief The CAN bus (see can_bus.hpp).
#include "oneshot/engine/can_bus.hpp"

#include <algorithm>
#include <stdexcept>

namespace oneshot::engine {

std::int64_t can_frame_bits(std::size_t payload_bytes, bool extended_ids) {
  if (payload_bytes > 8) throw std::invalid_argument("CAN frame: payload of " + std::to_string(payload_bytes) + " bytes (at most 8)");
  const std::int64_t g = extended_ids ? 54 : 34;
  const std::int64_t body = g + 8 * static_cast<std::int64_t>(payload_bytes);
  return body + 13 + (body - 1) / 4;  // Davis et al. 2007, eq. 1
}

CanBus::CanBus(Kernel& kernel, const CanBusConfig& config) : kernel_(kernel), config_(config), bit_time_(0) {
  if (config.bit_rate <= 0 || config.bit_rate > 1'000'000'000 || 1'000'000'000 % config.bit_rate != 0) {
    throw std::invalid_argument("CAN bus '" + config.name + "': bit rate " + std::to_string(config.bit_rate) +
                                " does not divide 1e9 (the bit time must be a whole number of ns)");
  }
  bit_time_ = Duration{1'000'000'000 / config.bit_rate};
  arbitrate_id_ = kernel_.add_handler("CAN " + config.name + " arbitration", [this](std::uint64_t) { arbitrate(); });
  end_id_ = kernel_.add_handler("CAN " + config.name + " end of frame", [this](std::uint64_t) { end_of_frame(); });
}

void CanBus::queue(std::uint32_t id, std::size_t payload_bytes, HandlerId on_delivered, std::uint64_t arg) {
  pending_.push(Pending{id, order_++, frame_time(payload_bytes), on_delivered, arg});
  stats_.max_pending = std::max(stats_.max_pending, pending_.size());
  if (!busy_ && !arbitration_scheduled_) {
    kernel_.schedule(kernel_.now(), EventClass::kBus, arbitrate_id_);
    arbitration_scheduled_ = true;
  }
}

void CanBus::arbitrate() {
  arbitration_scheduled_ = false;
  if (busy_ || pending_.empty()) return;
  current_ = pending_.top();
  pending_.pop();
  busy_ = true;
  kernel_.schedule(kernel_.now() + current_.length, EventClass::kDelivery, end_id_);
}

void CanBus::end_of_frame() {
  ++stats_.frames;
  stats_.busy += current_.length;
  busy_ = false;
  kernel_.schedule(kernel_.now(), EventClass::kDelivery, current_.handler, current_.arg);
  if (!pending_.empty() && !arbitration_scheduled_) {
    kernel_.schedule(kernel_.now(), EventClass::kBus, arbitrate_id_);
    arbitration_scheduled_ = true;
  }
}

}  // namespace oneshot::engine
