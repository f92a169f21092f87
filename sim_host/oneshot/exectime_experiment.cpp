/// @file exectime_experiment.cpp
/// @brief Experiment 5: the control job's execution time on this host (steady clock) and its
///        instruction counts under callgrind, half/complete × table/generic/nearest, both noise
///        models (see run_exectime in oneshot_experiments.hpp).
#include "oneshot_experiments.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "oneshot/util/child_process.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"

/// The function callgrind counts (see run_exectime): one replay of the recorded jobs.
extern "C" __attribute__((noinline)) void oneshot_exectime_replay(const std::function<void()>* replay) {
  (*replay)();
}

namespace oneshot::sim {

namespace {

struct Variant {
  const char* name;
  Approach approach;
  DiscretizerKind discretizer;
};
constexpr std::array<Variant, 6> kVariants = {{{"half_table", Approach::kB, DiscretizerKind::kTable},
                                               {"half_generic", Approach::kB, DiscretizerKind::kGeneric},
                                               {"complete_table", Approach::kC, DiscretizerKind::kTable},
                                               {"complete_generic", Approach::kC, DiscretizerKind::kGeneric},
                                               {"half_nearest", Approach::kB, DiscretizerKind::kNearest},
                                               {"complete_nearest", Approach::kC, DiscretizerKind::kNearest}}};

/// The jobs of 4 s of operation of the reference jitter scenario (approach B).
std::vector<JobRecord> exectime_jobs(const SimContext& ctx, const CommonOptions& opt) {
  const Scenario sc = uniform_scenario("exectime", 20'000, 0.2, 1.0, 4.0);
  RunOptions ro = run_options(opt, Approach::kB);
  ro.record_jobs = true;
  return simulate(ctx, sc, opt.seed, ro).job_records;
}

const Variant& find_variant(const std::string& name) {
  for (const Variant& v : kVariants)
    if (name == v.name) return v;
  throw std::invalid_argument("unknown variant '" + name + "'");
}

/// `path` for valgrind's --callgrind-out-file, where %p and %q{VAR} would be expanded.
std::string valgrind_literal(const std::string& path) {
  std::string out;
  for (char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

/// Instructions of one replay of `variant` under callgrind (output OUT/callgrind.<file_stem>.out),
/// or −1 when valgrind is unavailable.
double callgrind_instructions(const std::string& self, const CommonOptions& opt, const std::vector<std::string>& extra_args,
                              const std::string& variant, const std::string& file_stem) {
#if defined(__SANITIZE_ADDRESS__)
  return -1;  // valgrind cannot run an AddressSanitizer binary
#endif
  if (util::find_program("valgrind").empty()) return -1;
  util::make_directory(opt.out_dir);
  const std::string out_file = path_in(opt, "callgrind." + file_stem + ".out");
  util::ProcessSpec spec;
  spec.argv = {"valgrind", "--tool=callgrind", "--collect-atstart=no", "--toggle-collect=oneshot_exectime_replay",
               "--callgrind-out-file=" + valgrind_literal(out_file), self, "exectime-probe", "--variant", variant};
  spec.argv.insert(spec.argv.end(), extra_args.begin(), extra_args.end());
  const util::CapturedRun run = util::run_captured(spec);
  if (!run.status.success()) throw std::runtime_error("callgrind run failed (" + run.status.describe() + "):\n" + run.output);
  const std::string text = util::read_text_file(out_file, "callgrind output", std::size_t{256} << 20);
  std::istringstream in(text);
  std::string line;
  double total = -1;
  while (std::getline(in, line)) {
    if (line.rfind("summary:", 0) == 0 || line.rfind("totals:", 0) == 0) total = std::stod(line.substr(line.find(':') + 1));
  }
  if (total < 0) throw std::runtime_error(out_file + ": no instruction total");
  return total;
}

}  // namespace

int run_exectime_probe(const SimContext& ctx, const CommonOptions& opt, const std::string& variant) {
  const Variant& v = find_variant(variant);
  const std::vector<JobRecord> jobs = exectime_jobs(ctx, opt);
  RunOptions ro = run_options(opt, v.approach);
  ro.discretizer = v.discretizer;
  with_job_replay(ctx, ro, jobs, [&](const std::function<void()>& replay) { oneshot_exectime_replay(&replay); });
  std::cout << jobs.size() << "\n";
  return 0;
}

nlohmann::json run_exectime(const SimContext& ctx, const CommonOptions& opt, const std::string& self_path) {
  const std::vector<JobRecord> jobs = exectime_jobs(ctx, opt);
  const double jobs_per_4s = static_cast<double>(jobs.size());
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "exectime";
  j["target"] = "host";
  j["jobs_per_4s"] = jobs.size();
  const NoiseModel other = opt.noise == NoiseModel::kExact ? NoiseModel::kConstant : NoiseModel::kExact;
  const char* primary_name = opt.noise == NoiseModel::kExact ? "exact" : "constant";
  const char* other_name = opt.noise == NoiseModel::kExact ? "constant" : "exact";
  const NoiseModel models[2] = {opt.noise, other};
  const std::size_t variants = std::size(kVariants);
  const auto options_for = [&](std::size_t model) {
    CommonOptions o = opt;
    o.noise = models[model];
    return o;
  };
  // Host clock first, one variant at a time on a quiet process: batches of replays lasting
  // ≥ 50 ms each; the fastest batch is the least disturbed.
  std::vector<double> best_ns(2 * variants, 1e300);
  for (std::size_t i = 0; i < best_ns.size(); ++i) {
    const Variant& v = kVariants[i % variants];
    RunOptions ro = run_options(options_for(i / variants), v.approach);
    ro.discretizer = v.discretizer;
    with_job_replay(ctx, ro, jobs, [&](const std::function<void()>& replay) {
      for (int batch = 0; batch < 7; ++batch) {
        std::size_t reps = 0;
        const auto t0 = std::chrono::steady_clock::now();
        auto t1 = t0;
        do {
          replay();
          ++reps;
          t1 = std::chrono::steady_clock::now();
        } while (t1 - t0 < std::chrono::milliseconds(50));
        const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count() /
                          (static_cast<double>(reps) * jobs_per_4s);
        best_ns[i] = std::min(best_ns[i], ns);
      }
    });
  }
  // Then the instruction counts: callgrind runs are deterministic, so they run side by side
  // (opt.threads; each is a valgrind process of its own).
  std::vector<double> instructions(2 * variants, -1);
  if (!self_path.empty()) {
    util::make_directory(opt.out_dir);  // once, before the runs that write into it
    util::parallel_for(instructions.size(), util::worker_count(opt.threads), nullptr, [&](std::size_t i) {
      const CommonOptions o = options_for(i / variants);
      std::vector<std::string> extra = {"--number-format", to_string(o.format), "--noise-model",
                                        o.noise == NoiseModel::kExact ? "exact" : "constant", "--seed", std::to_string(o.seed)};
      if (!ctx.generated()) extra.insert(extra.end(), {"--plant", ctx.plant().source});
      // The primary noise model's outputs keep the variant's name; the other's add the model's.
      const std::string name = std::string(kVariants[i % variants].name) + (i < variants ? "" : std::string(".") + other_name);
      instructions[i] = callgrind_instructions(self_path, o, extra, kVariants[i % variants].name, name);
    });
  }
  for (std::size_t model = 0; model < 2; ++model) {
    nlohmann::json out;
    for (std::size_t k = 0; k < variants; ++k) {
      const std::size_t i = model * variants + k;
      nlohmann::json e = {{"host_ns_per_job", best_ns[i]}, {"host_us_per_4s", best_ns[i] * jobs_per_4s * 1e-3}};
      if (instructions[i] >= 0) {
        e["host_instructions_per_job"] = instructions[i] / jobs_per_4s;
        e["host_instructions_per_4s"] = instructions[i];
      } else {
        e["note"] = "valgrind not available (not installed, or a sanitizer build): instruction counts skipped";
      }
      out[kVariants[k].name] = e;
    }
    j["variants_by_noise_model"][model == 0 ? primary_name : other_name] = out;
  }
  j["variants"] = j["variants_by_noise_model"][primary_name];
  std::vector<std::vector<double>> rows;
  for (const Variant& v : kVariants) {
    const auto& p = j["variants_by_noise_model"][primary_name][v.name];
    const auto& q = j["variants_by_noise_model"][other_name][v.name];
    const auto ins = [](const nlohmann::json& e) {
      return e.contains("host_instructions_per_job") ? e["host_instructions_per_job"].get<double>() : 0.0;
    };
    rows.push_back({static_cast<double>(rows.size()), p["host_us_per_4s"].get<double>(), ins(p),
                    q["host_us_per_4s"].get<double>(), ins(q)});
  }
  util::write_csv(path_in(opt, "exectime.csv"),
            {"variant_index", std::string("us_per_4s_") + primary_name, std::string("instructions_per_job_") + primary_name,
             std::string("us_per_4s_") + other_name, std::string("instructions_per_job_") + other_name},
            rows);
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'exectime.png'\nset datafile separator ','\nset grid ytics\nset style fill solid 0.7\n"
      << "set boxwidth 0.35\nset xtics (\"half\\ntable\" 0, \"half\\ngeneric\" 1, \"complete\\ntable\" 2, \"complete\\ngeneric\" 3, "
         "\"half\\nnearest\" 4, \"complete\\nnearest\" 5)\n"
      << "set xrange [-0.6:5.6]\nset yrange [0:*]\nset offsets 0,0,graph 0.08,0\nset bmargin 4\nset key top left\n"
      << "set multiplot layout 1,2 title 'Control job over 4 s of operation (" << jobs.size() << " jobs, "
      << to_string(opt.format) << ", host)'\n"
      << "set ylabel 'accumulated execution time (us)'\n"
      << "plot 'exectime.csv' using ($1-0.18):2 skip 1 with boxes lc rgb '#4c72b0' title '" << primary_name << " Q', "
      << "'' using ($1+0.18):4 skip 1 with boxes lc rgb '#dd8452' title '" << other_name << " Q'\n"
      << "set ylabel 'instructions per job (callgrind)'\n"
      << "plot 'exectime.csv' using ($1-0.18):3 skip 1 with boxes lc rgb '#4c72b0' title '" << primary_name << " Q', "
      << "'' using ($1+0.18):5 skip 1 with boxes lc rgb '#dd8452' title '" << other_name << " Q'\n"
      << "unset multiplot\n";
    util::run_gnuplot(opt.out_dir, "exectime.gp", g.str());
  }
  j["files"] = {"exectime.csv", "exectime.png"};
  return j;
}

}  // namespace oneshot::sim
