/// @file random_stream.hpp
/// @brief The engine's named random streams (oneshot/engine/random_stream.hpp) under the
///        names the seed-000 code uses.
#pragma once

#include "oneshot/engine/random_stream.hpp"

namespace oneshot::sim {
using engine::RandomStream;
using engine::splitmix64;
using engine::stream_id;
using engine::stream_name;
}  // namespace oneshot::sim
