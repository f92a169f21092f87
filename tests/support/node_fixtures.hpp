/// @file node_fixtures.hpp
/// @brief One-channel fixtures of the node tests and the node-frame fuzzer: a Vector<double, 1>
///        from a number and the echo law (the controller commands the sample it received).
#pragma once

#include "oneshot/node/controller_node.hpp"

namespace oneshot::test {

/// The one-entry vector [x].
inline Vector<double, 1> v1(double x) {
  Vector<double, 1> v;
  v[0] = x;
  return v;
}

/// Control law u = y of the received sample; a command only on a fresh sample.
struct EchoLaw {
  node::LawResult compute(const node::Message<node::VectorPayload<double, 1>>& m, bool fresh, McuInstant,
                          Vector<double, 1>& u) {
    u = m.payload.value;
    return fresh ? node::LawResult::kSend : node::LawResult::kNone;
  }
};

}  // namespace oneshot::test
