# Precompiled headers of the release host build: nlohmann/json and the standard headers for the
# simulator's libraries (oneshot_sim, oneshot_engine, oneshot_design). Measured in a clean ci
# build: report.cpp 11.4 -> 6.8 s, ncs_loop.cpp 12.0 -> 8.8 s, cli_merge.cpp 11.5 -> 8.4 s. Not
# for the tests, nor in the sanitized build (the asan preset turns them off): there the long
# compiles got slower with a precompiled header loaded (likely GCC's garbage collector walking it on
# every pass: Eigen-heavy tests +20-70 %, e.g. eigen_reference.cpp 19.6 -> 33.7 s under ASan),
# more than the parsing saved (~0.5 s per test source). Only system headers: a change to a
# project header never invalidates them. ONESHOT_PCH=OFF builds without.
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
