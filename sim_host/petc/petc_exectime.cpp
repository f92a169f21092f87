/// @file petc_exectime.cpp
/// @brief One NUMRE arrival on the Cortex-M4F image vs the host build of the same node.
#include "petc_exectime.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "oneshot/app/petc_pil.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/sim/pil_link.hpp"

namespace oneshot::sim::petc {

namespace {

namespace pp = app::petc;
namespace pil = app::pil;

static_assert(pp::kHorizon == kHorizon, "the image's horizon is the study's");

/// The node's constants in double (the design's values), petc_pil.hpp layout.
void design_words(const PetcSetup& s, double (&w)[pp::kWordCount]) {
  const EstimatorModel& m = s.node_model.model;  // the block-diagonal basis the node runs in
  if (m.a.rows != pp::kStates) throw std::invalid_argument("petc exectime: the image is built for the 12-state model");
  for (std::size_t i = 0; i < pp::kStates; ++i) {
    for (std::size_t j = 0; j < pp::kStates; ++j) w[pp::kA + i * pp::kStates + j] = m.a(i, j);
    w[pp::kB + i] = m.b(i, 0);
    w[pp::kBw + i] = m.b_w(i, 0);
    w[pp::kC + i] = m.c(0, i);
    w[pp::kCbar + i] = m.c_bar(0, i);
  }
  w[pp::kW] = m.w;
  w[pp::kV] = m.v;
  w[pp::kFeedthrough] = s.mrci.feedthrough;
  std::size_t slow = 0;
  for (const MrciMode& mode : s.mrci.modes) {
    if (!mode.slow) {
      w[pp::kFastResidue] = mode.residue;
      w[pp::kFastPole] = mode.pole;
    } else {
      w[slow == 0 ? pp::kSlowResidue0 : pp::kSlowResidue1] = mode.residue;
      w[slow == 0 ? pp::kSlowPole0 : pp::kSlowPole1] = mode.pole;
      ++slow;
    }
  }
  w[pp::kReference] = s.opt.reference;
}

/// The case's controller thresholds.
const CaseSpec& find_case(const std::string& name) {
  static const std::vector<CaseSpec> cases = default_cases();
  for (const CaseSpec& c : cases)
    if (c.name == name) {
      if (c.controller != ControllerKind::kNumre || c.observer != ObserverKind::kAugmented)
        throw std::invalid_argument("petc exectime: case " + name +
                                    " does not run the augmented-model NUMRE the image carries (cases 3, 4, 5)");
      return c;
    }
  throw std::invalid_argument("petc exectime: unknown case '" + name + "' (3, 4 or 5)");
}

pp::ResetParams reset_params(const PetcSetup& s) {
  pp::ResetParams p;
  p.ratio = static_cast<std::uint32_t>(s.mrci.ratio);
  p.sample_at_update = s.opt.sample_at_update;
  p.frozen_noise = s.opt.frozen_noise;
  p.k_max = static_cast<std::uint32_t>(kHorizon);
  return p;
}

template <typename S>
std::unique_ptr<pp::Node<S>> make_node(const S (&w)[pp::kWordCount], const pp::ResetParams& p) {
  const pp::NodeArgs<S> a = pp::node_args(w, p);
  if (!pp::Node<S>::fits(a.model))
    throw std::invalid_argument("petc exectime: the model has a nonzero outside the image's HDD structure");
  return std::make_unique<pp::Node<S>>(a.model, a.acc, a.law, node::ModelDisturbance<S>{}, a.trigger, a.reference);
}

const char* cause_name(std::uint32_t c) {
  static const char* const names[] = {"none", "first", "periodic", "delta", "time", "reference"};
  return c < 6 ? names[c] : "?";
}

}  // namespace

ArrivalPlan plan_arrivals(const PetcSetup& setup, const ExectimeOptions& opt) {
  const CaseSpec& c = find_case(opt.case_name);
  ArrivalPlan plan;
  // N over the arrivals of the augmented-model NUMRE cases 3, 4, 5 at the seed (N = 0, the
  // first arrival, left out); y from the chosen case's measurements.
  std::vector<std::uint32_t> ns;
  std::vector<double> y_meas;
  for (const char* name : {"3", "4", "5"}) {
    RunTrace t;
    static_cast<void>(run_case(setup, find_case(name), opt.seed, &t));
    std::vector<std::uint32_t> case_ns;
    for (std::uint32_t n : t.multiplicity)
      if (n > 0) case_ns.push_back(n);
    ns.insert(ns.end(), case_ns.begin(), case_ns.end());
    std::sort(case_ns.begin(), case_ns.end());
    if (!case_ns.empty())
      plan.per_case.push_back({name, case_ns.size(), case_ns[(case_ns.size() - 1) / 2], case_ns.back()});
    if (c.name == name) y_meas = t.y_meas;
  }
  if (ns.empty()) throw std::invalid_argument("petc exectime: the cases' traces have a single arrival each");
  std::sort(ns.begin(), ns.end());
  double sum = 0;
  for (std::uint32_t n : ns) sum += n;
  plan.n_typical = ns[(ns.size() - 1) / 2];
  plan.n_mean = static_cast<std::uint32_t>(std::lround(sum / static_cast<double>(ns.size())));
  plan.n_max = ns.back();
  // Always N = 1, 2, 97 (case 3's largest at seed 1, the figures) and H = 200 (the
  // longest silence the safety allows) beside the study's median, mean and largest.
  std::vector<std::uint32_t> wanted = {1,           2,           97, static_cast<std::uint32_t>(kHorizon),
                                       plan.n_typical, std::max<std::uint32_t>(1, plan.n_mean), plan.n_max};
  for (std::uint32_t n : opt.extra) {
    if (n == 0) throw std::invalid_argument("petc exectime: a multiplicity must be >= 1");
    wanted.push_back(n);
  }
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  plan.k.push_back(0);
  for (std::uint32_t n : wanted) plan.k.push_back(plan.k.back() + n);
  if (plan.k.back() >= y_meas.size())
    throw std::invalid_argument("petc exectime: the multiplicities sum to " + std::to_string(plan.k.back()) +
                                " periods, beyond the run's " + std::to_string(y_meas.size()) + " (--steps)");
  for (std::uint32_t k : plan.k) plan.y.push_back(static_cast<float>(y_meas[k]));
  double wd[pp::kWordCount];
  design_words(setup, wd);
  wd[pp::kSigmaC] = c.sigma_c;
  wd[pp::kDeltaC] = c.delta_c;
  for (double x : wd) plan.words.push_back(pp::bits_of(static_cast<float>(x)));
  return plan;
}

std::vector<HostArrival> host_arrivals(const PetcSetup& setup, const ArrivalPlan& plan) {
  float wf[pp::kWordCount];
  double wd[pp::kWordCount];
  for (std::size_t i = 0; i < pp::kWordCount; ++i) wf[i] = pp::float_of(plan.words.at(i));
  design_words(setup, wd);
  wd[pp::kSigmaC] = static_cast<double>(wf[pp::kSigmaC]);
  wd[pp::kDeltaC] = static_cast<double>(wf[pp::kDeltaC]);
  const pp::ResetParams p = reset_params(setup);
  auto nf = make_node(wf, p);
  auto nd = make_node(wd, p);
  std::vector<HostArrival> out;
  for (std::size_t a = 0; a < plan.k.size(); ++a) {
    HostArrival h;
    const std::uint64_t before = nf->macs();
    h.cause = static_cast<std::uint32_t>(nf->on_arrival(plan.k[a], plan.y[a]));
    h.macs = nf->macs() - before;
    h.multiplicity = nf->estimator().last_multiplicity();
    static_cast<void>(nd->on_arrival(plan.k[a], static_cast<double>(plan.y[a])));
    for (std::size_t i = 0; i < pp::kStates; ++i) h.x_hat.push_back(nf->estimator().state()[i]);
    double diff = 0, scale = 0;
    for (std::size_t l = 0; l < pp::Node<float>::kEntries; ++l) {
      h.cascade.push_back(nf->last_cascade()[l]);
      h.d_hat.push_back(nf->last_cascade_d_hat()[l]);
      diff = std::max(diff, std::fabs(static_cast<double>(nf->last_cascade()[l]) - nd->last_cascade()[l]));
      scale = std::max(scale, std::fabs(nd->last_cascade()[l]));
    }
    h.max_rel_diff_double = scale > 0 ? diff / scale : diff;
    out.push_back(std::move(h));
  }
  return out;
}

nlohmann::json run_exectime(const PetcSetup& setup, const ExectimeOptions& opt) {
  const ArrivalPlan plan = plan_arrivals(setup, opt);
  const std::vector<HostArrival> host = host_arrivals(setup, plan);
  PilOptions po;
  po.target = "cortex-m4f";
  po.image_name = "oneshot-cortex-m4f-petc.elf";
  po.firmware_dir = opt.firmware_dir;
  po.plugin_path = opt.plugin_path;
  po.count_instructions = true;
  po.timeout_ms = 20000;  // an arrival at N ≈ 100 is ~10^6 instructions; QEMU on a busy machine
  PilLink link(po);
  link.request(pil::Type::kCalibrate, pil::Frame{});
  for (std::size_t first = 0; first < pp::kWordCount; first += pp::kWordsPerFrame) {
    pil::Frame f;
    pil::Writer w(f);
    w.u(static_cast<std::uint32_t>(first), 2);
    for (std::size_t i = first; i < std::min<std::size_t>(pp::kWordCount, first + pp::kWordsPerFrame); ++i) w.u(plan.words[i], 4);
    link.request(pp::kPetcLoad, f);
  }
  const pp::ResetParams rp = reset_params(setup);
  pil::Frame rf;
  pil::Writer rw(rf);
  rw.u(rp.ratio, 1);
  rw.u(rp.sample_at_update ? 1U : 0U, 1);
  rw.u(rp.frozen_noise ? 1U : 0U, 1);
  rw.u(rp.k_max, 4);
  const pil::Frame reset_reply = link.request(pp::kPetcReset, rf);
  pil::Reader rr(reset_reply);
  const std::uint32_t node_bytes = rr.u(4);

  nlohmann::json arrivals = nlohmann::json::array();
  bool all_identical = true;
  std::vector<nlohmann::json> rows;
  for (std::size_t a = 0; a < plan.k.size(); ++a) {
    pil::Frame f;
    pil::Writer w(f);
    w.u(plan.k[a], 4);
    w.u(pp::bits_of(plan.y[a]), 4);
    const pil::Frame reply = link.request(pp::kPetcArrival, f);
    pil::Reader r(reply);
    const std::uint32_t cause = r.u(1);
    const std::uint32_t n = r.u(4);
    const std::uint32_t macs = r.u(4);
    bool same_x = true;
    for (std::size_t i = 0; i < pp::kStates; ++i) same_x = same_x && r.u(4) == pp::bits_of(host[a].x_hat[i]);
    if (r.bad()) throw PilError("petc image: short arrival reply");
    bool same_u = true, same_d = true;
    for (std::uint32_t what = 0; what < 2; ++what) {
      const std::vector<float>& ref = what == 0 ? host[a].cascade : host[a].d_hat;
      bool& same = what == 0 ? same_u : same_d;
      for (std::size_t first = 0; first < ref.size(); first += pp::kWordsPerFrame) {
        pil::Frame q;
        pil::Writer qw(q);
        qw.u(what, 1);
        qw.u(static_cast<std::uint32_t>(first), 2);
        const pil::Frame got = link.request(pp::kPetcRead, q);
        pil::Reader gr(got);
        for (std::size_t l = first; l < std::min(ref.size(), first + pp::kWordsPerFrame); ++l) {
          const bool eq = gr.u(4) == pp::bits_of(ref[l]);
          same = same && eq;
        }
        if (gr.bad()) throw PilError("petc image: short cascade reply");
      }
    }
    const bool identical = same_x && same_u && same_d && cause == host[a].cause && n == host[a].multiplicity &&
                           macs == host[a].macs;
    all_identical = all_identical && identical;
    rows.push_back({{"k", plan.k[a]},
                    {"N", n},
                    {"cause", cause_name(cause)},
                    {"macs", macs},
                    {"host_macs", host[a].macs},
                    {"bit_identical_x_hat", same_x},
                    {"bit_identical_cascade", same_u},
                    {"bit_identical_d_hat", same_d},
                    {"bit_identical", identical},
                    {"float_vs_double_cascade_rel_diff", host[a].max_rel_diff_double}});
  }
  const std::vector<std::uint64_t> counts = link.instruction_counts();
  if (counts.size() != 1 + plan.k.size())
    throw PilError("instruction counter: expected " + std::to_string(1 + plan.k.size()) + " windows, got " +
                   std::to_string(counts.size()));
  const std::uint64_t overhead = counts[0];
  nlohmann::json by_n = nlohmann::json::object();
  std::uint64_t most = 0;
  std::uint32_t n_most = 0;
  for (std::size_t a = 0; a < rows.size(); ++a) {
    const std::uint64_t insns = counts[1 + a] - overhead;
    by_n[std::to_string(rows[a]["N"].get<std::uint32_t>())] = insns;
    if (insns >= most) {
      most = insns;
      n_most = rows[a]["N"].get<std::uint32_t>();
    }
    rows[a]["instructions"] = insns;
    const auto macs = rows[a]["macs"].get<std::uint64_t>();
    rows[a]["instructions_per_mac"] = macs > 0 ? static_cast<double>(insns) / static_cast<double>(macs) : 0.0;
    arrivals.push_back(rows[a]);
  }
  nlohmann::json j;
  j["experiment"] = "petc_exectime";
  j["target"] = link.info().target;
  j["image"] = link.image();
  j["number_format"] = "float (IEEE single precision on the FPv4-SP FPU, -ffp-contract=off)";
  j["case"] = opt.case_name;
  j["seed"] = opt.seed;
  j["horizon_H"] = kHorizon;
  j["n_typical"] = plan.n_typical;
  j["n_mean"] = plan.n_mean;
  j["n_max"] = plan.n_max;
  for (const CaseMultiplicity& m : plan.per_case)
    j["multiplicity_by_case"][m.name] = {{"arrivals", m.arrivals}, {"median", m.median}, {"max", m.max}};
  j["counter"] = "QEMU TCG plugin insn_window: guest instructions of one PetcController::on_arrival, marker overhead "
                 "subtracted";
  j["marker_overhead_instructions"] = overhead;
  j["arrivals"] = arrivals;
  j["instructions_by_N"] = by_n;  // per arrival, keyed by N ("0": the first arrival)
  j["largest_N_measured"] = rows.empty() ? 0U : rows.back()["N"].get<std::uint32_t>();
  j["instructions_max"] = most;
  j["instructions_max_at_N"] = n_most;
  j["all_bit_identical_to_host_float"] = all_identical;
  j["node_bytes"] = node_bytes;
  const auto [flash, ram] = image_memory(link.image());
  j["flash_bytes"] = flash;
  j["ram_static_bytes"] = ram;
  j["ram_limit_bytes"] = 64 * 1024;
  j["stack_peak_bytes"] = link.stack_peak_bytes();
  const std::string stack_file = link.image() + ".stack.txt";
  if (std::filesystem::is_regular_file(stack_file)) {
    std::istringstream in(util::read_text_file(stack_file, "stack bound", 4096));
    std::size_t bound = 0;
    if (in >> bound) {
      j["stack_bound_bytes"] = bound;
      j["ram_total_bound_bytes"] = ram + bound;
    }
  }
  return j;
}

std::string exectime_markdown(const nlohmann::json& j) {
  std::ostringstream md;
  md << "| arrival k | N | cause | instructions | multiply-adds | instructions / multiply-add | M4F = host float (bits) "
        "| float vs double (cascade, rel.) |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& a : j.at("arrivals")) {
    char line[300];
    std::snprintf(line, sizeof line, "| %u | %u | %s | %llu | %llu | %.2f | %s | %.1e |\n", a.at("k").get<unsigned>(),
                  a.at("N").get<unsigned>(), a.at("cause").get<std::string>().c_str(),
                  static_cast<unsigned long long>(a.at("instructions").get<std::uint64_t>()),
                  static_cast<unsigned long long>(a.at("macs").get<std::uint64_t>()),
                  a.at("instructions_per_mac").get<double>(), a.at("bit_identical").get<bool>() ? "yes" : "**no**",
                  a.at("float_vs_double_cascade_rel_diff").get<double>());
    md << line;
  }
  md << "\nImage `" << std::filesystem::path(j.at("image").get<std::string>()).filename().string()
     << "`: flash " << j.at("flash_bytes") << " B, static RAM " << j.at("ram_static_bytes") << " B (node "
     << j.at("node_bytes") << " B) of " << j.at("ram_limit_bytes") << " B, stack peak " << j.at("stack_peak_bytes")
     << " B";
  if (j.contains("stack_bound_bytes")) md << ", stack bound (sum of all frames) " << j.at("stack_bound_bytes") << " B";
  md << ". N = 0 is the first arrival (no prediction). N over the arrivals of cases 3, 4, 5 (seed " << j.at("seed")
     << "): median " << j.at("n_typical") << ", mean " << j.at("n_mean") << ", largest " << j.at("n_max")
     << "; y from case " << j.at("case").get<std::string>() << "'s measurements.\n";
  return md.str();
}

}  // namespace oneshot::sim::petc
