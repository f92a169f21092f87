/// @file delay_model.cpp
/// @brief Delay models (see delay_model.hpp).
#include "oneshot/engine/delay_model.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "oneshot/engine/json_fields.hpp"
#include "oneshot/util/file_io.hpp"

namespace oneshot::engine {
namespace {

/// Largest delay parameter accepted anywhere (µs): one hour.
constexpr double kMaxDelayUs = 3.6e9;

Duration rounded_ns(double ns, Duration cap, bool& clamped) {
  if (!(ns < static_cast<double>(cap.count()))) {  // also catches NaN and +inf
    clamped = true;
    return cap;
  }
  return Duration{std::llround(ns)};
}

std::string ms(Duration d) {
  std::ostringstream o;
  o << static_cast<double>(d.count()) * 1e-6;
  return o.str();
}

}  // namespace

Duration DelayModel::draw(RandomStream& rng, std::uint64_t index, bool& clamped) const {
  clamped = false;
  switch (kind) {
    case Kind::kConstant:
      return constant;
    case Kind::kUniform:
      if (resolution.count() > 1) {
        return min + resolution * rng.uniform_int(0, (max - min).count() / resolution.count());
      }
      return Duration{rng.uniform_int(min.count(), max.count())};
    case Kind::kPoissonPeriods:
      return shift + period * rng.poisson(mean_periods);
    case Kind::kTrace:
      return trace[index % trace.size()];
    case Kind::kLognormal:
      return shift + rounded_ns(median_ns * std::exp(sigma * rng.normal()), cap - shift, clamped);
    case Kind::kPareto:
      return shift + rounded_ns(rng.pareto(scale_ns, alpha), cap - shift, clamped);
  }
  return constant;
}

Duration DelayModel::lower_bound() const {
  switch (kind) {
    case Kind::kConstant:
      return constant;
    case Kind::kUniform:
      return min;
    case Kind::kPoissonPeriods:
    case Kind::kLognormal:
      return shift;
    case Kind::kPareto:  // x_m past the cap: every draw is the cap (sample() clamps)
      return std::min(shift + Duration{static_cast<std::int64_t>(std::floor(scale_ns))}, cap);
    case Kind::kTrace: {
      Duration m = trace.front();
      for (Duration d : trace) m = std::min(m, d);
      return m;
    }
  }
  return Duration{0};
}

std::optional<Duration> DelayModel::upper_bound() const {
  switch (kind) {
    case Kind::kConstant:
      return constant;
    case Kind::kUniform:
      return min + resolution * ((max - min) / resolution);
    case Kind::kTrace: {
      Duration m = trace.front();
      for (Duration d : trace) m = std::max(m, d);
      return m;
    }
    case Kind::kPoissonPeriods:
    case Kind::kLognormal:
    case Kind::kPareto:
      break;
  }
  return std::nullopt;
}

double DelayModel::mean_ns() const {
  switch (kind) {
    case Kind::kConstant:
      return static_cast<double>(constant.count());
    case Kind::kUniform: {
      const std::int64_t steps = (max - min) / resolution;
      return static_cast<double>(min.count()) + 0.5 * static_cast<double>(resolution.count()) * static_cast<double>(steps);
    }
    case Kind::kPoissonPeriods:
      return static_cast<double>(shift.count()) + mean_periods * static_cast<double>(period.count());
    case Kind::kLognormal: {
      // A draw is shift + min(X, c), c = cap − shift (the clamp of sample()), X = m e^{σZ}:
      // E min(X, c) = m e^{σ²/2} Φ((ln(c/m) − σ²)/σ) + c (1 − Φ(ln(c/m)/σ)), Φ(x) = erfc(−x/√2)/2.
      const double c = static_cast<double>((cap - shift).count());
      const double sh = static_cast<double>(shift.count());
      if (!(sigma > 0)) return sh + std::fmin(median_ns, c);
      const double l = std::log(c / median_ns);
      const auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
      return sh + median_ns * std::exp(0.5 * sigma * sigma) * phi((l - sigma * sigma) / sigma) + c * phi(-l / sigma);
    }
    case Kind::kPareto: {
      // A draw is shift + min(X, c), c = cap − shift, X Pareto (x_m, α): E min(X, c) = ∫₀ᶜ P(X > t) dt
      // = x_m (1 + ((c/x_m)^{1−α} − 1)/(1 − α)) for c > x_m (x_m (1 + ln(c/x_m)) at α = 1), c for c ≤ x_m:
      // finite for every α, the cap being finite (the uncapped mean x_m α/(α − 1) is its limit for α > 1).
      const double c = static_cast<double>((cap - shift).count());
      const double sh = static_cast<double>(shift.count());
      if (c <= scale_ns) return sh + c;
      const double l = std::log(c / scale_ns);
      const double e = 1 - alpha;
      return sh + scale_ns * (1 + (e == 0 ? l : std::expm1(e * l) / e));
    }
    case Kind::kTrace: {
      double sum = 0;
      for (Duration d : trace) sum += static_cast<double>(d.count());
      return sum / static_cast<double>(trace.size());
    }
  }
  return 0;
}

std::string DelayModel::describe() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::kConstant:
      o << "constant " << ms(constant) << " ms";
      break;
    case Kind::kUniform:
      o << "uniform " << ms(min) << "-" << ms(max) << " ms";
      break;
    case Kind::kPoissonPeriods:
      o << "Poisson(" << mean_periods << ") x " << ms(period) << " ms + " << ms(shift) << " ms";
      break;
    case Kind::kTrace:
      o << "trace " << trace_path << " (" << trace.size() << " delays)";
      break;
    case Kind::kLognormal:
      o << "lognormal median " << median_ns * 1e-6 << " ms sigma " << sigma << " + " << ms(shift) << " ms";
      break;
    case Kind::kPareto:
      o << "Pareto scale " << scale_ns * 1e-6 << " ms alpha " << alpha << " + " << ms(shift) << " ms";
      break;
  }
  return o.str();
}

std::vector<Duration> parse_delay_trace(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || (line != "delay_us" && line != "delay_us\r")) {
    throw InputError(source + ": line 1: expected the header 'delay_us'");
  }
  std::vector<Duration> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    bool digits = line.size() <= 10;
    for (char c : line) digits = digits && c >= '0' && c <= '9';
    if (!digits || std::stod(line) > kMaxDelayUs) {
      throw InputError(source + ": line " + std::to_string(n) + ": expected one integer delay in [0, 3.6e9] us");
    }
    out.push_back(from_us(std::stoll(line)));
  }
  if (out.empty()) throw InputError(source + ": the trace has no delays");
  return out;
}

DelayModel parse_delay_model(const nlohmann::json& j, const std::string& field, const std::string& base_dir) {
  if (!j.is_object()) throw InputError("field '" + field + "': must be an object");
  const std::string model = string_of(j, field, "model");
  DelayModel d;
  const auto us = [&](const char* key, bool optional, double fallback) {
    return Duration{std::llround(1000 * number_in(j, field, key, 0, kMaxDelayUs, optional, fallback))};
  };
  // A heavy tail: a scale (µs, stored in ns), a shape parameter in [shape_min, shape_max],
  // an optional shift_us and cap_us (cap > shift is checked below).
  const auto heavy_tail = [&](DelayModel::Kind kind, const char* scale_key, double& scale_ns, const char* shape_key,
                              double shape_min, double shape_max, double& shape) {
    require_keys(j, field, {"model", scale_key, shape_key, "shift_us", "cap_us"});
    d.kind = kind;
    scale_ns = 1000 * number_in(j, field, scale_key, 1e-3, kMaxDelayUs);
    shape = number_in(j, field, shape_key, shape_min, shape_max);
    d.shift = us("shift_us", true, 0);
    d.cap = us("cap_us", true, kMaxDelayUs);
  };
  if (model == "constant") {
    require_keys(j, field, {"model", "delay_us"});
    d.kind = DelayModel::Kind::kConstant;
    d.constant = us("delay_us", false, 0);
  } else if (model == "uniform") {
    require_keys(j, field, {"model", "min_us", "max_us", "resolution_us"});
    d.kind = DelayModel::Kind::kUniform;
    d.min = us("min_us", false, 0);
    d.max = us("max_us", false, 0);
    if (d.max < d.min) throw InputError("field '" + field + ".max_us': below min_us");
    d.resolution = us("resolution_us", true, 0.001);
    if (d.resolution.count() <= 0) throw InputError("field '" + field + ".resolution_us': must be positive");
  } else if (model == "poisson_periods") {
    require_keys(j, field, {"model", "mean_periods", "period_us", "offset_us"});
    d.kind = DelayModel::Kind::kPoissonPeriods;
    d.mean_periods = number_in(j, field, "mean_periods", 0, 100);
    d.period = us("period_us", false, 0);
    if (d.period.count() <= 0) throw InputError("field '" + field + ".period_us': must be positive");
    d.shift = us("offset_us", true, 0);
  } else if (model == "trace") {
    require_keys(j, field, {"model", "file"});
    d.kind = DelayModel::Kind::kTrace;
    std::filesystem::path path = string_of(j, field, "file");
    if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
    d.trace_path = path.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      throw InputError("field '" + field + ".file': " + d.trace_path + " is not a readable regular file");
    }
    const std::string text =
        util::read_text_file_as<InputError>(d.trace_path, "delay trace", "field '" + field + ".file': ", std::size_t{1} << 28);
    d.trace = parse_delay_trace(text, d.trace_path);
  } else if (model == "lognormal") {
    heavy_tail(DelayModel::Kind::kLognormal, "median_us", d.median_ns, "sigma", 0, 10, d.sigma);
  } else if (model == "pareto") {
    heavy_tail(DelayModel::Kind::kPareto, "scale_us", d.scale_ns, "alpha", 0.05, 100, d.alpha);
  } else {
    throw InputError("field '" + field + ".model': unknown delay model '" + model +
                     "' (constant, uniform, poisson_periods, trace, lognormal, pareto)");
  }
  if ((d.kind == DelayModel::Kind::kLognormal || d.kind == DelayModel::Kind::kPareto) && d.cap <= d.shift) {
    throw InputError("field '" + field + ".cap_us': must exceed shift_us");
  }
  return d;
}

}  // namespace oneshot::engine
