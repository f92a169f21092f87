/// @file assert_hook.hpp
/// @brief Host port of the core's assert handler: a replaceable hook.
///
/// By default a failed invariant prints file, line and expression and aborts. Tests
/// install a hook that throws, so that an invariant violation is a test failure.
#pragma once

namespace oneshot::host {

/// Called with the failing invariant; must not return (throw or abort).
using AssertHook = void (*)(const char* file, int line, const char* expression);

/// Installs `hook` (nullptr restores the default) and returns the previous one.
AssertHook set_assert_hook(AssertHook hook);

}  // namespace oneshot::host
