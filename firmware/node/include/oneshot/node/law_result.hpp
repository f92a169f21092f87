/// @file law_result.hpp
/// @brief What a controller node's control law decided on one computation (controller_node.hpp).
#pragma once

#include <cstdint>

namespace oneshot::node {

/// What a control law's compute() decided.
enum class [[nodiscard]] LawResult : std::uint8_t {
  kSend,   ///< Send the command it wrote.
  kNone,   ///< Nothing to send (e.g. no fresh measurement).
  kReset,  ///< Its estimator turned non-finite and was reset (counted by the law): nothing sent.
};

}  // namespace oneshot::node
