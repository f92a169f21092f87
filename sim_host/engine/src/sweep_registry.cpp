/// @file sweep_registry.cpp
/// @brief Summarizers of merged sweeps (see sweep_registry.hpp).
#include "oneshot/engine/sweep_registry.hpp"

#include <map>
#include <mutex>
#include <stdexcept>

namespace oneshot::engine {
namespace {

std::map<std::string, SweepSummarizer>& registry() {
  static std::map<std::string, SweepSummarizer> r;
  return r;
}
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

void register_summarizer(const std::string& study, const std::string& experiment, SweepSummarizer summarizer) {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[study + " " + experiment] = std::move(summarizer);
}

const SweepSummarizer& find_summarizer(const std::string& study, const std::string& experiment) {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  const auto it = registry().find(study + " " + experiment);
  if (it != registry().end()) return it->second;
  std::string known;
  for (const auto& [k, v] : registry()) known += (known.empty() ? "" : ", ") + k;
  throw std::invalid_argument("no study experiment '" + study + " " + experiment + "' can merge sweeps (known: " + known +
                              ")");
}

}  // namespace oneshot::engine
