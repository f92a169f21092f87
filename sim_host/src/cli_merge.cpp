/// @file cli_merge.cpp
/// @brief `oneshot-sim merge`: joins the shard files of a sweep into its result.
#include <iostream>
#include <memory>
#include <sstream>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/strict_json.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {
namespace {

/// Largest shard file read (bytes): a shard holds a few numbers per run.
constexpr std::size_t kMaxShardBytes = std::size_t{1} << 30;

engine::SweepResults read_shard(const std::string& path) {
  nlohmann::json j;
  try {
    // Bounded read (a directory, device or oversized file is named as such); duplicate keys refused.
    j = util::parse_json_strict(util::read_text_file(path, "shard file", kMaxShardBytes));
  } catch (const util::FileError& e) {
    throw std::invalid_argument(e.what());
  } catch (const util::JsonError& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  try {
    return engine::shard_from_json(j);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

}  // namespace

void register_merge_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> files;
    std::string out = "out/merged";
    std::string json;
    bool no_plots = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Join the shard files of a sweep (written with --shard i/N) into the result of one run, byte for byte");
  cmd->add_option("shards", o->files, "shard files (every i/N of one sweep, any order)")->required();
  cmd->add_option("--out", o->out, "output folder for the experiment's files")->capture_default_str();
  cmd->add_option("--json", o->json, "write the summary as JSON to PATH ('-' for standard output)");
  cmd->add_flag("--no-plots", o->no_plots, "write CSV files only (no gnuplot)");
  cmd->callback([o]() {
    std::vector<engine::SweepResults> shards;
    for (const std::string& f : o->files) shards.push_back(read_shard(f));
    const engine::SweepResults all = engine::merge_shards(shards);
    const auto& summarize = find_summarizer(all.spec.study, all.spec.experiment);
    const nlohmann::json j = summarize(all, o->out, !o->no_plots);
    if (!o->json.empty()) util::write_json(o->json, j);
    if (o->json != "-") {
      std::cout << all.spec.study << " " << all.spec.experiment << ": " << shards.size() << " shards, "
                << all.spec.runs() << " runs merged, written to " << o->out << "\n";
    }
  });
}

}  // namespace oneshot::sim
