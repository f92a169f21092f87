/// @file pil_runtime.hpp
/// @brief The MCU side of the PIL link shared by every firmware image: byte reception from
///        the UART interrupt, frame transmission, the serve loop (hello at boot, the requests
///        every image answers, retransmitted requests answered from the last reply) and the
///        fault and failed-invariant reports. Each image supplies only its job dispatch.
///
/// Freestanding: no heap, no I/O library; the SoC is injected as template parameters whose
/// contracts are checked below. Reset, vectors and the stack paint are in startup.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/mcu/rx_ring.hpp"

/// Instruction-count markers: the QEMU plugin counts from the first instruction of begin to
/// the first of end. Every image brackets its job with them, and kCalibrate calls them back
/// to back (the overhead subtracted from each window).
extern "C" inline __attribute__((noinline, used)) void oneshot_job_begin() { __asm__ volatile("" ::: "memory"); }
/// See oneshot_job_begin().
extern "C" inline __attribute__((noinline, used)) void oneshot_job_end() { __asm__ volatile("" ::: "memory"); }
/// Deepest stack use since reset, bytes (startup.cpp paints the free stack).
extern "C" std::uint32_t oneshot_stack_peak_bytes();

namespace oneshot::app::pil {

/// What an image is, as its kHello reply states it (after the protocol version; the stack
/// peak follows).
struct ImageInfo {
  std::uint8_t target;  ///< 0 Cortex-M0, 1 Cortex-M4F.
  std::uint8_t format;  ///< 0 float, 1 fixed point.
  std::uint8_t disc;    ///< 0 table, 1 generic, 2 table at the nearest grid point.
  std::uint8_t states;  ///< n.
  std::uint8_t inputs;  ///< m.
  std::uint8_t outputs;  ///< p.
};

/// The reply type of request type `t` (kReply OR-ed in).
constexpr Type reply_type(Type t) {
  return static_cast<Type>(static_cast<std::uint8_t>(t) | static_cast<std::uint8_t>(Type::kReply));
}

/// `r` becomes the empty reply to `q`: same sequence number, the reply type.
constexpr void begin_reply(const Frame& q, Frame& r) {
  r.seq = q.seq;
  r.type = reply_type(q.type);
  r.length = 0;
}

/// `r` becomes a fault frame whose payload is `code` (kFaultHard, kFaultUnknownRequest, …).
constexpr void write_fault(Frame& r, std::uint32_t code) {
  r.type = Type::kFault;
  Writer w(r);
  w.u(code, 4);
}

/// Refuses a request whose payload does not decode (wrong length or value): a fault reply
/// naming it, never a job run on zeros.
constexpr void malformed(Frame& r) { write_fault(r, kFaultMalformedRequest); }

/// `r` becomes a failed-invariant report: the line, then as much of the file name as fits.
constexpr void write_assert(Frame& r, const char* file, int line) {
  r.type = Type::kFault;
  Writer w(r);
  w.u(static_cast<std::uint32_t>(line), 4);
  for (std::size_t i = 0; file[i] != '\0' && r.length < kMaxPayload; ++i) w.u(static_cast<std::uint8_t>(file[i]), 1);
}

/// `r` becomes the kHello reply of an image: version, `info`, stack peak in bytes (2 bytes).
constexpr void write_hello(Frame& r, const ImageInfo& info, std::uint32_t stack_peak_bytes) {
  r.type = reply_type(Type::kHello);
  Writer w(r);
  w.u(kProtocolVersion, 1);
  w.u(info.target, 1);
  w.u(info.format, 1);
  w.u(info.disc, 1);
  w.u(info.states, 1);
  w.u(info.inputs, 1);
  w.u(info.outputs, 1);
  w.u(stack_peak_bytes, 2);
}

namespace detail {
/// A byte sink, for the contract checks only.
struct ByteSink {
  void operator()(std::uint8_t) const {}
};
template <typename T, typename = void>
struct is_uart : std::false_type {};
template <typename T>
struct is_uart<T, std::void_t<decltype(T::init()), decltype(T::put(std::uint8_t{})),
                              decltype(T::drain(ByteSink{}))>> : std::true_type {};
template <typename T, typename = void>
struct is_idle_wakeup : std::false_type {};
template <typename T>
struct is_idle_wakeup<T, std::void_t<decltype(T::init()), decltype(T::arm()), decltype(T::disarm()),
                                     decltype(T::acknowledge())>> : std::true_type {};
template <typename T, typename = void>
struct is_cpu : std::false_type {};
template <typename T>
struct is_cpu<T, std::void_t<decltype(T::interrupts_off()), decltype(T::interrupts_on()),
                             decltype(T::wait_for_interrupt())>> : std::true_type {};
}  // namespace detail

/// The PIL link over one UART. Uart: init(), put(byte) (blocking), drain(sink) (hands every
/// received byte to sink). IdleWakeup: init(), arm() and disarm() around the sleep for input
/// (a timer where the simulator needs one to wake, otherwise empty), acknowledge(). Cpu:
/// interrupts_off(), interrupts_on(), wait_for_interrupt().
template <typename Uart, typename IdleWakeup, typename Cpu>
class PilRuntime {
  static_assert(detail::is_uart<Uart>::value, "Uart: init(), put(std::uint8_t), drain(sink)");
  static_assert(detail::is_idle_wakeup<IdleWakeup>::value, "IdleWakeup: init(), arm(), disarm(), acknowledge()");
  static_assert(detail::is_cpu<Cpu>::value, "Cpu: interrupts_off(), interrupts_on(), wait_for_interrupt()");

 public:
  /// Largest encoded frame: every byte escaped, plus the two delimiters.
  static constexpr std::size_t kMaxEncoded = 2 * (kMaxPayload + 5) + 2;

  /// The UART and the idle wake-up timer; interrupts stay masked (the image enables them).
  static void init() {
    Uart::init();
    IdleWakeup::init();
  }

  /// The UART receive interrupt's body.
  static void on_uart_rx() { Uart::drain([](std::uint8_t b) { rx_.push(b); }); }

  /// The idle wake-up interrupt's body.
  static void on_idle_wakeup() { IdleWakeup::acknowledge(); }

  /// Next received byte; sleeps until an interrupt when there is none.
  static std::uint8_t next_byte() {
    for (;;) {
      std::uint8_t b = 0;
      Cpu::interrupts_off();
      if (rx_.pop(b)) {
        IdleWakeup::disarm();
        Cpu::interrupts_on();
        return b;
      }
      IdleWakeup::arm();
      Cpu::wait_for_interrupt();  // a pending interrupt ends it even with PRIMASK set
      on_uart_rx();               // whatever woke us
      Cpu::interrupts_on();
    }
  }

  /// Sends `f`, encoded, over the UART (out of line: one copy of the encoder per image).
  __attribute__((noinline)) static void send(const Frame& f) {
    std::uint8_t out[kMaxEncoded];
    const std::size_t n = encode(f, out);
    for (std::size_t i = 0; i < n; ++i) Uart::put(out[i]);
  }

  /// A fault: reported once over the link, then the core stops.
  [[noreturn]] static void report_fault(std::uint32_t code) {
    Frame f;
    write_fault(f, code);
    halt_after(f);
  }

  /// A failed invariant: its line and file reported once over the link, then the core stops.
  [[noreturn]] static void report_assert(const char* file, int line) {
    Frame f;
    write_assert(f, file, line);
    halt_after(f);
  }

  /// One request-reply session: the decoder and the last reply. Handle is called as
  /// handle(request, reply) with the reply begun (sequence number, reply type, empty) for every
  /// request except those every image answers alike: kHello, kCalibrate, kEcho.
  class Session {
   public:
    /// Feeds one received byte; a complete request is answered (returns true: progress, not a
    /// status, so the main loop may ignore it).
    template <typename Handle>
    bool feed(std::uint8_t byte, const ImageInfo& info, Handle&& handle) {
      if (!decoder_.feed(byte)) return false;
      const Frame& q = decoder_.frame();
      // A repeated sequence number is a retransmission: the reply was lost, not the request;
      // it is sent again, and the request is never run twice.
      if (!have_last_ || q.seq != last_.seq || last_.type != reply_type(q.type)) {
        answer(q, info, handle);
        have_last_ = true;
      }
      send(last_);
      return true;
    }
    /// Number of frames the decoder dropped (corrupt or too long).
    std::uint32_t dropped() const { return decoder_.dropped(); }

   private:
    template <typename Handle>
    void answer(const Frame& q, const ImageInfo& info, Handle& handle) {
      begin_reply(q, last_);
      switch (q.type) {
        case Type::kHello:
          if (q.length != 0) return malformed(last_);
          return write_hello(last_, info, oneshot_stack_peak_bytes());
        case Type::kCalibrate:
          if (q.length != 0) return malformed(last_);
          oneshot_job_begin();
          oneshot_job_end();
          return;
        case Type::kEcho:
          for (std::size_t i = 0; i < q.length; ++i) last_.payload[i] = q.payload[i];
          last_.length = q.length;
          return;
        default:
          return handle(q, last_);
      }
    }
    Decoder decoder_;
    Frame last_;
    bool have_last_ = false;
  };

  /// The image's main loop: the hello frame, then every request answered for ever.
  template <typename Handle>
  [[noreturn]] static void serve(const ImageInfo& info, Handle&& handle) {
    Frame hello;
    write_hello(hello, info, oneshot_stack_peak_bytes());
    send(hello);
    Session session;
    for (;;) session.feed(next_byte(), info, handle);
  }

 private:
  [[noreturn]] static void halt_after(const Frame& f) {
    send(f);
    for (;;) {
    }
  }
  static inline mcu::RxRing rx_;
};

}  // namespace oneshot::app::pil
