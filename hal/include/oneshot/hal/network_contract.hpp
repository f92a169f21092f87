/// @file network_contract.hpp
/// @brief The network interface a node needs, as a compile-time contract.
///
/// A board with a network offers, beside the board contract (board_contract.hpp):
///   Board::Net   static std::uint8_t address();
///                this node's address on the network
///                static bool send(std::uint8_t destination, const std::uint8_t* data, std::size_t size);
///                queues one frame of `size` bytes for `destination`; false when it cannot
///                (interface full, frame too large): the caller counts it, nothing blocks
///                static std::size_t receive(std::uint8_t& source, std::uint8_t* data, std::size_t capacity);
///                moves the oldest received frame into `data` and returns its size, or 0 when
///                none is waiting (a frame longer than `capacity` is dropped and counted by the port)
/// Frames are opaque bytes (node/message.hpp encodes them); delivery is unreliable and
/// unordered in general (the simulator's links decide). Checked by static_assert in the
/// nodes; no virtual dispatch. Ports: hal/host_sim (the simulator's links and CAN bus).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace oneshot::hal {

namespace detail {
template <typename T, typename = void>
struct has_net_send : std::false_type {};
template <typename T>
struct has_net_send<
    T, std::enable_if_t<std::is_same_v<decltype(T::send(std::uint8_t{}, static_cast<const std::uint8_t*>(nullptr),
                                                         std::size_t{})),
                                       bool>>> : std::true_type {};

template <typename T, typename = void>
struct has_net_receive : std::false_type {};
template <typename T>
struct has_net_receive<
    T, std::enable_if_t<std::is_same_v<decltype(T::receive(std::declval<std::uint8_t&>(),
                                                            static_cast<std::uint8_t*>(nullptr), std::size_t{})),
                                       std::size_t>>> : std::true_type {};

template <typename T, typename = void>
struct has_net_address : std::false_type {};
template <typename T>
struct has_net_address<T, std::enable_if_t<std::is_same_v<decltype(T::address()), std::uint8_t>>> : std::true_type {};
}  // namespace detail

/// Board::Net fulfils the network contract (send, receive, address).
template <typename Board>
inline constexpr bool kHasNetwork = detail::has_net_send<typename Board::Net>::value &&
                                    detail::has_net_receive<typename Board::Net>::value &&
                                    detail::has_net_address<typename Board::Net>::value;

}  // namespace oneshot::hal
