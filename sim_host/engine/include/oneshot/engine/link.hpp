/// @file link.hpp
/// @brief A point-to-point network link: its delay model, its loss process, FIFO or
///        reordering delivery, and its counters.
///
/// For every message the link draws a loss decision (stream "link/<name>/loss") and a
/// delay (stream "link/<name>/delay"), both always, so changing the loss rate does not
/// move the delays and vice versa. A message sent at t arrives at t + d; with "fifo" it
/// arrives no earlier than the message sent before it (a queue that never overtakes);
/// otherwise messages may overtake one another (reordering).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "oneshot/engine/delay_model.hpp"
#include "oneshot/engine/frame_layout.hpp"
#include "oneshot/engine/loss_model.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// A link's definition.
struct LinkConfig {
  std::string name;   ///< Identifier (names the random streams).
  DelayModel delay;   ///< Delay distribution.
  LossModel loss;     ///< Loss process.
  bool fifo = false;  ///< Never deliver out of order.
  FrameLayout frame{};  ///< What its frames look like (for the fault models, frame_faults.hpp).
};

/// Counters of a link.
struct LinkStatistics {
  std::uint64_t sent = 0;        ///< Messages handed to the link.
  std::uint64_t lost = 0;        ///< Lost.
  std::uint64_t reordered = 0;   ///< Arrived before a message sent earlier.
  std::uint64_t clamped = 0;     ///< Delays clamped to the model's cap.
  Duration max_delay{0};         ///< Largest delay of a delivered message.
};

/// One direction of a connection between two nodes.
class Link {
 public:
  /// Link `config` for run seed `seed`.
  Link(const LinkConfig& config, std::uint64_t seed);
  /// The fate of a message sent at `sent`: nothing when lost, else its arrival time.
  std::optional<SimTime> transmit(SimTime sent);
  /// Counters.
  const LinkStatistics& statistics() const { return stats_; }
  /// The definition.
  const LinkConfig& config() const { return config_; }

 private:
  LinkConfig config_;
  RandomStream delay_rng_;
  LossProcess loss_;
  SimTime last_arrival_{0};
  std::uint64_t index_ = 0;
  LinkStatistics stats_{};
};

}  // namespace oneshot::engine
