/// @file sweep.cpp
/// @brief Monte Carlo sweeps, shards and merging (see sweep.hpp).
#include "oneshot/engine/sweep.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "oneshot/util/progress_bar.hpp"

namespace oneshot::engine {
namespace {

constexpr const char* kShardFormat = "oneshot-sweep-shard/1";

const nlohmann::json& field(const nlohmann::json& j, const char* key, const std::string& where) {
  const auto it = j.find(key);
  if (it == j.end()) throw std::invalid_argument(where + "." + key + ": missing");
  return *it;
}

std::vector<std::string> names(const nlohmann::json& j, const char* key, const std::string& where) {
  const nlohmann::json& a = field(j, key, where);
  if (!a.is_array()) throw std::invalid_argument(where + "." + key + ": must be an array of names");
  std::vector<std::string> out;
  for (const auto& e : a) {
    if (!e.is_string()) throw std::invalid_argument(where + "." + key + ": must be an array of names");
    out.push_back(e.get<std::string>());
  }
  return out;
}

}  // namespace

Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  const auto bad = [&]() { return std::invalid_argument("--shard '" + text + "': expected i/N with 0 <= i < N <= 100000"); };
  if (slash == std::string::npos || slash == 0 || slash + 1 >= text.size()) throw bad();
  for (std::size_t k = 0; k < text.size(); ++k)
    if (k != slash && (text[k] < '0' || text[k] > '9')) throw bad();
  if (slash > 6 || text.size() - slash - 1 > 6) throw bad();
  Shard s;
  s.index = std::stoul(text.substr(0, slash));
  s.count = std::stoul(text.substr(slash + 1));
  if (s.count == 0 || s.count > 100000 || s.index >= s.count) throw bad();
  return s;
}

nlohmann::json SweepSpec::to_json() const {
  return {{"study", study},         {"experiment", experiment}, {"approaches", approaches}, {"scenarios", scenarios},
          {"first_seed", first_seed}, {"seeds", seeds},           {"metrics", metrics},       {"config", config}};
}

SweepSpec SweepSpec::from_json(const nlohmann::json& j) {
  const std::string w = "spec";
  if (!j.is_object()) throw std::invalid_argument("spec: must be an object");
  SweepSpec s;
  const auto str = [&](const char* k) {
    const nlohmann::json& v = field(j, k, w);
    if (!v.is_string()) throw std::invalid_argument(w + "." + k + ": must be a string");
    return v.get<std::string>();
  };
  s.study = str("study");
  s.experiment = str("experiment");
  s.approaches = names(j, "approaches", w);
  s.scenarios = names(j, "scenarios", w);
  s.metrics = names(j, "metrics", w);
  const nlohmann::json& fs = field(j, "first_seed", w);
  const nlohmann::json& n = field(j, "seeds", w);
  if (!fs.is_number_unsigned()) throw std::invalid_argument("spec.first_seed: must be a non-negative integer");
  if (!n.is_number_unsigned() || n.get<std::uint64_t>() > 10'000'000) {
    throw std::invalid_argument("spec.seeds: must be an integer in [0, 1e7]");
  }
  s.first_seed = fs.get<std::uint64_t>();
  s.seeds = n.get<std::size_t>();
  s.config = field(j, "config", w);
  if (s.approaches.empty() || s.scenarios.empty() || s.metrics.empty()) {
    throw std::invalid_argument("spec: approaches, scenarios and metrics must not be empty");
  }
  // A shard file is read back from disk: its sweep must fit in memory (runs x metrics values)
  // and its names must stay one CSV cell each.
  constexpr double kMaxValues = 1e9;
  if (static_cast<double>(s.approaches.size()) * static_cast<double>(s.scenarios.size()) * static_cast<double>(s.seeds) *
          static_cast<double>(s.metrics.size()) > kMaxValues) {
    throw std::invalid_argument("spec: more than 1e9 values (approaches x scenarios x seeds x metrics)");
  }
  for (const std::string& m : s.metrics) {
    if (m.empty() || m.find_first_of(",\"\r\n") != std::string::npos) {
      throw std::invalid_argument("spec.metrics: '" + m + "' is not a plain name (no comma, quote or line break)");
    }
  }
  return s;
}

std::size_t SweepResults::metric(const std::string& name) const {
  for (std::size_t m = 0; m < spec.metrics.size(); ++m)
    if (spec.metrics[m] == name) return m;
  throw std::invalid_argument("sweep " + spec.experiment + ": no metric '" + name + "'");
}

bool SweepResults::complete() const {
  for (std::uint8_t d : done)
    if (d == 0) return false;
  return true;
}

SweepResults run_sweep(const SweepSpec& spec, const Shard& shard, unsigned threads, const RunFunction& run,
                       const std::string& label) {
  SweepResults r;
  r.spec = spec;
  r.shard = shard;
  const std::size_t nm = spec.metrics.size();
  r.values.assign(spec.runs() * nm, std::numeric_limits<double>::quiet_NaN());
  r.done.assign(spec.runs(), 0);
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < spec.runs(); ++i)
    if (shard.owns(i)) mine.push_back(i);
  const std::size_t per_a = spec.scenarios.size() * spec.seeds;
  util::ProgressBar bar(label, mine.size());
  util::parallel_for(mine.size(), util::worker_count(threads), &bar, [&](std::size_t i) {
    const std::size_t idx = mine[i];
    const std::size_t a = idx / per_a;
    const std::size_t s = (idx % per_a) / spec.seeds;
    const std::size_t k = idx % spec.seeds;
    const std::vector<double> v = run(a, s, spec.first_seed + k);
    if (v.size() != nm) {
      throw std::logic_error("sweep " + spec.experiment + ": a run returned " + std::to_string(v.size()) +
                             " values for " + std::to_string(nm) + " metrics");
    }
    for (std::size_t m = 0; m < nm; ++m) r.values[idx * nm + m] = v[m];
    r.done[idx] = 1;
  });
  return r;
}

nlohmann::json shard_to_json(const SweepResults& results) {
  nlohmann::json runs = nlohmann::json::array();
  const std::size_t nm = results.spec.metrics.size();
  for (std::size_t i = 0; i < results.done.size(); ++i) {
    if (results.done[i] == 0) continue;
    nlohmann::json row = nlohmann::json::array({i});
    for (std::size_t m = 0; m < nm; ++m) {
      const double v = results.values[i * nm + m];
      if (!std::isfinite(v)) {
        throw std::runtime_error("sweep " + results.spec.experiment + ": run " + std::to_string(i) + " metric '" +
                                 results.spec.metrics[m] + "' is not finite");
      }
      row.push_back(v);
    }
    runs.push_back(row);
  }
  return {{"format", kShardFormat},
          {"spec", results.spec.to_json()},
          {"shard", {{"index", results.shard.index}, {"count", results.shard.count}}},
          {"runs", runs}};
}

SweepResults shard_from_json(const nlohmann::json& j) {
  if (!j.is_object() || j.value("format", std::string()) != kShardFormat) {
    throw std::invalid_argument(std::string("not a sweep shard (field 'format' must be \"") + kShardFormat + "\")");
  }
  SweepResults r;
  r.spec = SweepSpec::from_json(field(j, "spec", "shard file"));
  const nlohmann::json& sh = field(j, "shard", "shard file");
  if (!sh.is_object() || !sh.contains("index") || !sh.contains("count") || !sh["index"].is_number_unsigned() ||
      !sh["count"].is_number_unsigned()) {
    throw std::invalid_argument("shard: must be {\"index\": i, \"count\": N}");
  }
  r.shard.index = sh["index"].get<std::size_t>();
  r.shard.count = sh["count"].get<std::size_t>();
  if (r.shard.count == 0 || r.shard.index >= r.shard.count) throw std::invalid_argument("shard: index must be below count");
  const std::size_t nm = r.spec.metrics.size();
  r.values.assign(r.spec.runs() * nm, std::numeric_limits<double>::quiet_NaN());
  r.done.assign(r.spec.runs(), 0);
  const nlohmann::json& runs = field(j, "runs", "shard file");
  if (!runs.is_array()) throw std::invalid_argument("runs: must be an array");
  for (std::size_t n = 0; n < runs.size(); ++n) {
    const nlohmann::json& row = runs[n];
    const std::string w = "runs[" + std::to_string(n) + "]";
    if (!row.is_array() || row.size() != nm + 1 || !row[0].is_number_unsigned()) {
      throw std::invalid_argument(w + ": must be [run index, one number per metric]");
    }
    const std::size_t i = row[0].get<std::size_t>();
    if (i >= r.spec.runs() || !r.shard.owns(i) || r.done[i] != 0) {
      throw std::invalid_argument(w + ": run " + std::to_string(i) + " is outside the shard or repeated");
    }
    for (std::size_t m = 0; m < nm; ++m) {
      if (!row[m + 1].is_number() || !std::isfinite(row[m + 1].get<double>())) {
        throw std::invalid_argument(w + ": values must be finite numbers");
      }
      r.values[i * nm + m] = row[m + 1].get<double>();
    }
    r.done[i] = 1;
  }
  return r;
}

SweepResults merge_shards(const std::vector<SweepResults>& shards) {
  if (shards.empty()) throw std::invalid_argument("merge: no shard files");
  SweepResults out = shards.front();
  const nlohmann::json spec = out.spec.to_json();
  out.shard = Shard{};
  std::fill(out.done.begin(), out.done.end(), std::uint8_t{0});
  const std::size_t nm = out.spec.metrics.size();
  for (std::size_t n = 0; n < shards.size(); ++n) {
    const SweepResults& s = shards[n];
    if (s.spec.to_json() != spec) {
      throw std::invalid_argument("merge: shard " + std::to_string(n + 1) + " belongs to another sweep (its spec differs)");
    }
    for (std::size_t i = 0; i < s.done.size(); ++i) {
      if (s.done[i] == 0) continue;
      if (out.done[i] != 0) throw std::invalid_argument("merge: run " + std::to_string(i) + " is in two shards");
      for (std::size_t m = 0; m < nm; ++m) out.values[i * nm + m] = s.values[i * nm + m];
      out.done[i] = 1;
    }
  }
  for (std::size_t i = 0; i < out.done.size(); ++i) {
    if (out.done[i] == 0) {
      throw std::invalid_argument("merge: run " + std::to_string(i) + " of " + std::to_string(out.done.size()) +
                                  " is missing (give every shard of the sweep)");
    }
  }
  return out;
}

std::string shard_file_name(const std::string& experiment, const Shard& shard) {
  return experiment + ".shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".json";
}

nlohmann::json write_shard_file(const SweepResults& results, const std::string& out_dir, const std::string& experiment,
                                const Shard& shard) {
  util::make_directory(out_dir);
  nlohmann::json j = shard_to_json(results);
  util::write_json(util::path_in(out_dir, shard_file_name(experiment, shard)), j);
  return j;
}

}  // namespace oneshot::engine
