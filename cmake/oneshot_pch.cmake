# Precompiled headers of the host build: the system headers nearly every host source parses
# (nlohmann/json, the standard library; GoogleTest in the tests): ~3 s less CPU per simulator
# source (measured: report.cpp 11.4 -> 7.8 s, ncs_loop.cpp 12.0 -> 8.7 s), ~0.5 s per test
# source. The heavy ones used by a few sources only (Eigen in the test oracles, CLI11 whose
# global validators are emitted in every includer) stay out: a larger precompiled header costs
# its load time in every source. Only system headers: a change to a project header never
# invalidates them. ONESHOT_PCH=OFF builds without (e.g. to check that every source includes
# what it uses).
option(ONESHOT_PCH "Precompile the common system headers of the host targets" ON)

# Standard headers used by most host sources.
set(ONESHOT_PCH_STD_HEADERS
  <algorithm> <array> <cmath> <cstddef> <cstdint> <cstdio> <cstring> <functional> <limits> <map>
  <memory> <optional> <sstream> <stdexcept> <string> <utility> <vector>)

# oneshot_host_pch(<target>): the target's sources get nlohmann/json and the standard headers
# precompiled.
function(oneshot_host_pch target)
  if(ONESHOT_PCH)
    target_precompile_headers(${target} PRIVATE <nlohmann/json.hpp> ${ONESHOT_PCH_STD_HEADERS})
  endif()
endfunction()

# oneshot_test_pch(<target>): GoogleTest added to the host set (the test support library's, reused
# by every test executable through oneshot_test_pch_reuse()).
function(oneshot_test_pch target)
  if(ONESHOT_PCH)
    target_precompile_headers(${target} PRIVATE <gtest/gtest.h> <nlohmann/json.hpp> ${ONESHOT_PCH_STD_HEADERS})
  endif()
endfunction()

# oneshot_test_pch_reuse(<target> <from>): <target> compiles against <from>'s precompiled header.
function(oneshot_test_pch_reuse target from)
  if(ONESHOT_PCH)
    target_precompile_headers(${target} REUSE_FROM ${from})
  endif()
endfunction()
