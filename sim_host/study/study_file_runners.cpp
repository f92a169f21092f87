/// @file study_file_runners.cpp
/// @brief The adapters of study_file_runner.hpp: the dropping, sod, oneshot and petc studies'
///        mappings, runners and reports behind one interface, with each study's refusals of the
///        options it does not take.
#include "study_file_runner.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "oneshot/util/output_files.hpp"
#include "study_bench.hpp"
#include "study_check.hpp"
#include "study_dropping_report.hpp"
#include "study_dropping_runner.hpp"
#include "study_dropping_study.hpp"
#include "study_file_report.hpp"
#include "study_oneshot_study.hpp"
#include "study_petc_study.hpp"
#include "study_sod_runner.hpp"

namespace oneshot::study {
namespace {

/// Refuses --max-duration: these studies' runs take the file's duration_s.
void refuse_max_duration(const FileCommand& c, const char* study) {
  if (c.max_duration)
    throw engine::InputError(std::string("field '--max-duration': a ") + study + " file's runs take its duration_s");
}

/// Refuses what `study run` of these studies does not take: --analytic (`no_analytic`: why) and
/// --max-duration.
void refuse_run_options(const FileCommand& c, const char* study, const char* no_analytic) {
  if (c.analytic) throw engine::InputError(std::string("field '--analytic': ") + no_analytic);
  refuse_max_duration(c, study);
}

class DroppingRunner final : public FileStudyRunner {
 public:
  explicit DroppingRunner(std::shared_ptr<const DroppingStudy> s) : s_(std::move(s)) {}
  const char* study() const override { return "dropping"; }
  void add_design(nlohmann::json& r) const override { add_dropping_design(r, *s_); }
  std::string describe(const nlohmann::json& r) const override { return describe_dropping(r); }

  void run(const FileCommand& c) const override {
    refuse_run_options(c, "dropping", "no exact cost for the dropping loop (its filters run on what arrives)");
    run_file_sweep(c, [&](const engine::Shard& part) { return run_dropping_sweep(*s_, c.seeds, c.threads, part); }, dropping_run_outputs);
  }

  /// The sweep, the summary, the cost plot, the traced runs, OUT/report.md and OUT/report.json.
  void report(const nlohmann::json& check, const FileCommand& c) const override {
    const DroppingStudy& s = *s_;
    refuse_max_duration(c, "dropping");
    if (c.trace && c.trace_names.empty()) throw engine::InputError("field '--trace': an empty approach name");
    const std::vector<std::size_t> traced = trace_selection(s.approaches, s.source, c.trace_names);
    util::make_directory(c.out);
    const engine::SweepResults r = run_dropping_sweep(s, c.seeds, c.threads, engine::Shard{});
    nlohmann::json j = dropping_run_outputs(r, c.out, false);
    for (const auto& f : write_dropping_cost_plot(r, c.out, !c.no_plots)) j["files"].push_back(f);
    nlohmann::json traces = write_dropping_traces(s, traced, c.out, !c.no_plots);
    mark_same_cost_as_sweep(traces, r, traced);
    j["traces"] = traces;
    nlohmann::json resolution = check;  // the grid that ran: --seeds overrides the file's count
    resolution["seeds"]["count"] = r.spec.seeds;
    resolution["grid"]["runs"] = r.spec.runs();
    const std::string md = dropping_report_markdown(s, c.file, describe_resolution(resolution) + describe_dropping(resolution), r, j,
                                                    c.no_plots ? "" : "table.png", traces, !c.no_plots);
    util::write_text((std::filesystem::path(c.out) / "report.md").string(), md);
    util::write_json((std::filesystem::path(c.out) / "report.json").string(), j);
    std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(c.out) / "report.md").string() << "\n";
  }

  nlohmann::json bench(const FileCommand& c) const override {
    refuse_max_duration(c, "dropping");
    return dropping_bench(*s_, c.seeds, c.threads);
  }

 private:
  std::shared_ptr<const DroppingStudy> s_;
};

class SodRunner final : public FileStudyRunner {
 public:
  explicit SodRunner(std::shared_ptr<const SodStudy> s) : s_(std::move(s)) {}
  const char* study() const override { return "sod"; }
  void add_design(nlohmann::json& r) const override { add_sod_design(r, *s_); }
  std::string describe(const nlohmann::json& r) const override { return describe_sod(r); }
  void run(const FileCommand& c) const override {
    refuse_run_options(c, "sod", "no exact cost for the sod study (its estimator runs on what arrives)");
    run_file_sweep(c, [&](const engine::Shard& part) { return run_sod_sweep(*s_, c.seeds, c.threads, part); }, sod_run_outputs);
  }
  void report(const nlohmann::json& check, const FileCommand& c) const override {
    report_sod_file(*s_, c.file, check, c.out, c.seeds, c.threads, !c.no_plots, c.max_duration, c.trace ? &c.trace_names : nullptr);
  }
  nlohmann::json bench(const FileCommand& c) const override {
    refuse_max_duration(c, "sod");
    return sod_bench(*s_, c.seeds, c.threads);
  }

 private:
  std::shared_ptr<const SodStudy> s_;
};

class OneShotRunner final : public FileStudyRunner {
 public:
  explicit OneShotRunner(std::shared_ptr<const OneShotFileStudy> s) : s_(std::move(s)) {}
  const char* study() const override { return "oneshot"; }
  void add_design(nlohmann::json& r) const override { add_oneshot_design(r, *s_); }
  std::string describe(const nlohmann::json& r) const override { return describe_oneshot(r); }
  void run(const FileCommand& c) const override {
    refuse_run_options(c, "oneshot", "a oneshot file runs the emulated board (`oneshot table1 --analytic`: the linear board)");
    run_file_sweep(c, [&](const engine::Shard& part) { return run_oneshot_sweep(*s_, c.seeds, c.threads, part); }, oneshot_run_outputs);
  }
  void report(const nlohmann::json& check, const FileCommand& c) const override {
    refuse_max_duration(c, "oneshot");
    if (c.trace) throw engine::InputError("field '--trace': no traces of a oneshot file (`oneshot-sim oneshot run` traces a run)");
    nlohmann::json resolution = check;  // the grid that runs: --seeds overrides the file's count
    if (c.seeds != 0) {
      resolution["seeds"]["count"] = c.seeds;
      resolution["grid"]["runs"] = s_->approaches.size() * s_->scenarios.size() * c.seeds;
    }
    oneshot_report_command(*s_, c.file, describe_resolution(resolution) + describe_oneshot(resolution), c.seeds, c.threads, c.out,
                           !c.no_plots);
  }
  nlohmann::json bench(const FileCommand& c) const override {
    refuse_max_duration(c, "oneshot");
    return oneshot_bench(*s_, c.seeds, c.threads);
  }

 private:
  std::shared_ptr<const OneShotFileStudy> s_;
};

class PetcRunner final : public FileStudyRunner {
 public:
  explicit PetcRunner(std::shared_ptr<const PetcStudy> s) : s_(std::move(s)) {}
  const char* study() const override { return "petc"; }
  void add_design(nlohmann::json& r) const override { add_petc_design(r, *s_); }
  std::string describe(const nlohmann::json& r) const override { return describe_petc(r); }
  void run(const FileCommand& c) const override {
    refuse_run_options(c, "petc", "no exact cost for the petc loop (its triggers run on what is measured)");
    run_file_sweep(c, [&](const engine::Shard& part) { return run_petc_sweep(*s_, c.seeds, c.threads, part); }, petc_run_outputs);
  }
  void report(const nlohmann::json& check, const FileCommand& c) const override { petc_report_command(*s_, check, c); }
  nlohmann::json bench(const FileCommand& c) const override {
    refuse_max_duration(c, "petc");
    return petc_bench(*s_, c.seeds, c.threads);
  }

 private:
  std::shared_ptr<const PetcStudy> s_;
};

}  // namespace

void run_file_sweep(const FileCommand& c, const std::function<engine::SweepResults(const engine::Shard&)>& sweep,
                    SweepOutputs outputs) {
  const engine::Shard part = engine::parse_shard(c.shard);
  const auto start = std::chrono::steady_clock::now();
  const engine::SweepResults r = sweep(part);  // a refusal from inside the sweep (sod's δt design) leaves nothing written
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  util::make_directory(c.out);
  nlohmann::json j;
  if (!part.whole()) {
    j = engine::write_shard_file(r, c.out, "run", part);
  } else {
    j = outputs(r, c.out, !c.no_plots);
    if (c.json != "-") std::cout << j.at("markdown").get<std::string>() << "order: " << j.at("order_text").get<std::string>() << "\n";
  }
  if (!c.json.empty()) util::write_json(c.json, j);
  if (c.json != "-") std::cout << "study run: " << r.spec.runs() << " runs, wall time " << wall << " s, written to " << c.out << "\n";
}

nlohmann::json resolve_file_study(const engine::StudyFile& generic) {
  nlohmann::json r = generic.study == "sod" ? resolve_sod_study(generic) : resolve_study(generic);
  if (!r.contains("links")) r["links"] = nlohmann::json::array();  // a file without links (oneshot)
  return r;
}

std::unique_ptr<const FileStudyRunner> map_file_study(const engine::StudyFile& generic, const std::string& path) {
  if (generic.study == "dropping") return std::make_unique<DroppingRunner>(map_dropping_study(engine::load_study(path, &dropping_schema())));
  if (generic.study == "sod") return std::make_unique<SodRunner>(map_sod_study(engine::load_study(path, &sod_schema())));
  if (generic.study == "oneshot") return std::make_unique<OneShotRunner>(map_oneshot_study(engine::load_study(path, &oneshot_schema())));
  if (generic.study == "petc") return std::make_unique<PetcRunner>(map_petc_study(engine::load_study(path, &petc_schema())));
  return nullptr;
}

std::vector<std::pair<std::string, SweepOutputs>> file_study_finishers() {
  return {{"run-dropping", dropping_run_outputs}, {"run-sod", sod_run_outputs}, {"run-oneshot", oneshot_run_outputs},
          {"run-petc", petc_run_outputs}};
}

}  // namespace oneshot::study
