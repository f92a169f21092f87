/// @file loss_model.hpp
/// @brief Packet losses: none, independent (Bernoulli), or bursts (Gilbert–Elliott).
///
/// Gilbert–Elliott: a two-state Markov chain per link, good G and bad B, moving
/// G → B with probability p and B → G with probability r after each packet; a packet is
/// lost with probability k in G and h in B. The chain starts in its stationary law
/// π_B = p/(p + r), so the loss rate is (1 − π_B) k + π_B h from the first packet; with
/// k = 0, h = 1 (Gilbert's model) bursts of losses are geometric with mean 1/r.
/// Every packet consumes exactly two uniforms (loss, transition) whatever the outcome, so
/// the loss stream stays aligned across parameter changes.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine {

/// A link's loss process parameters.
struct LossModel {
  /// Model kind.
  enum class Kind : std::uint8_t { kNone, kBernoulli, kGilbertElliott };
  Kind kind = Kind::kNone;   ///< Model.
  double p = 0;              ///< Bernoulli: loss probability; GE: P(G → B).
  double r = 0;              ///< GE: P(B → G).
  double loss_good = 0;      ///< GE: loss probability in G (k).
  double loss_bad = 1;       ///< GE: loss probability in B (h).

  /// Stationary loss probability.
  double loss_rate() const;
  /// One-line description.
  std::string describe() const;
};

/// The loss process of one link (holds the Gilbert–Elliott state).
class LossProcess {
 public:
  /// Process of `model` drawing from `rng`.
  LossProcess(const LossModel& model, RandomStream rng);
  /// Whether the next packet is lost.
  bool next_lost();
  /// True while in the bad state (Gilbert–Elliott).
  bool bad() const { return bad_; }

 private:
  LossModel model_;
  RandomStream rng_;
  bool bad_ = false;
  bool started_ = false;
};

/// Parses {"model": "none"|"bernoulli"|"gilbert_elliott", …}; std::invalid_argument naming
/// `field` and the key.
LossModel parse_loss_model(const nlohmann::json& j, const std::string& field);

}  // namespace oneshot::engine
