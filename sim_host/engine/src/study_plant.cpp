/// @file study_plant.cpp
/// @brief The plant section of a study file (see study_parse_detail.hpp).
#include <cmath>
#include <vector>

#include "oneshot/dimension_limits.hpp"
#include "study_parse_detail.hpp"

namespace oneshot::engine::detail {
namespace {

using nlohmann::json;

/// A matrix as rows of finite numbers; absent and optional → 0×0.
DenseMatrix matrix(const json& j, const std::string& where, const char* key, bool optional) {
  const std::string f = where + "." + key;
  const auto it = j.find(key);
  if (it == j.end()) {
    if (optional) return {};
    throw InputError("field '" + f + "': missing");
  }
  if (!it->is_array() || it->empty() || it->size() > 64) throw InputError("field '" + f + "': must be an array of 1-64 rows");
  DenseMatrix m;
  m.rows = it->size();
  for (std::size_t i = 0; i < m.rows; ++i) {
    const json& row = (*it)[i];
    if (!row.is_array() || row.empty() || (i > 0 && row.size() != m.cols) || row.size() > 64) {
      throw InputError("field '" + f + "': rows must be non-empty arrays of equal length");
    }
    m.cols = row.size();
    for (const json& v : row) {
      if (!v.is_number() || !std::isfinite(v.get<double>())) throw InputError("field '" + f + "': entries must be finite numbers");
      m.values.push_back(v.get<double>());
    }
  }
  return m;
}

void shape(const DenseMatrix& m, std::size_t r, std::size_t c, const std::string& f) {
  if (m.rows != r || m.cols != c) {
    throw InputError("field '" + f + "': is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) + ", expected " +
                     std::to_string(r) + "x" + std::to_string(c));
  }
}

/// Symmetric positive semidefinite (LDLᵀ with a relative tolerance), or absent.
void psd(const DenseMatrix& m, std::size_t n, const std::string& f) {
  if (m.rows == 0) return;
  shape(m, n, n, f);
  double scale = 0;
  for (double v : m.values) scale = std::fmax(scale, std::fabs(v));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (std::fabs(m(i, j) - m(j, i)) > 1e-12 * scale) throw InputError("field '" + f + "': not symmetric");
  std::vector<double> l(n * n, 0.0);
  std::vector<double> d(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    double djj = m(j, j);
    for (std::size_t k = 0; k < j; ++k) djj -= l[j * n + k] * l[j * n + k] * d[k];
    if (djj < -1e-10 * scale) throw InputError("field '" + f + "': not positive semidefinite");
    d[j] = djj > 1e-14 * scale ? djj : 0;
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = m(i, j);
      for (std::size_t k = 0; k < j; ++k) s -= l[i * n + k] * l[j * n + k] * d[k];
      if (d[j] == 0 && std::fabs(s) > 1e-10 * scale) throw InputError("field '" + f + "': not positive semidefinite");
      l[i * n + j] = d[j] > 0 ? s / d[j] : 0;
    }
  }
}

void dimension_limits(std::size_t n, std::size_t m, std::size_t p, std::size_t w, const std::string& f) {
  if (n > kMaxStates || m > kMaxInputs || p > kMaxOutputs || w > kMaxDisturbances) {
    throw InputError("field '" + f + "': dimensions n = " + std::to_string(n) + ", m = " + std::to_string(m) + ", p = " +
                     std::to_string(p) + ", w = " + std::to_string(w) + " exceed the supported limits (kMaxStates " +
                     std::to_string(kMaxStates) + ", kMaxInputs " + std::to_string(kMaxInputs) + ", kMaxOutputs " +
                     std::to_string(kMaxOutputs) + ", kMaxDisturbances " + std::to_string(kMaxDisturbances) + ")");
  }
}

}  // namespace

PlantSpec parse_plant(const json& j, const std::string& f) {
  require_keys(j, f, {"file", "continuous", "discrete"});
  if (j.size() != 1) throw InputError("field '" + f + "': give exactly one of file, continuous, discrete");
  PlantSpec p;
  if (j.contains("file")) {
    p.kind = PlantSpec::Kind::kFile;
    p.file = string_of(j, f, "file");
    return p;
  }
  if (j.contains("continuous")) {
    const std::string g = f + ".continuous";
    const json& c = j["continuous"];
    require_keys(c, g, {"A", "B", "B_w", "C", "Q_c", "Q1c", "Q2c"});
    p.kind = PlantSpec::Kind::kContinuous;
    ContinuousModel& m = p.continuous;
    m.a = matrix(c, g, "A", false);
    const std::size_t n = m.a.rows;
    shape(m.a, n, n, g + ".A");
    m.b = matrix(c, g, "B", false);
    shape(m.b, n, m.b.cols, g + ".B");
    m.bw = matrix(c, g, "B_w", true);
    if (m.bw.rows != 0) shape(m.bw, n, m.bw.cols, g + ".B_w");
    m.c = matrix(c, g, "C", false);
    shape(m.c, m.c.rows, n, g + ".C");
    dimension_limits(n, m.b.cols, m.c.rows, m.bw.cols, g);
    m.qc = matrix(c, g, "Q_c", false);
    psd(m.qc, n, g + ".Q_c");
    m.q1c = matrix(c, g, "Q1c", true);
    psd(m.q1c, n, g + ".Q1c");
    m.q2c = matrix(c, g, "Q2c", true);
    psd(m.q2c, m.b.cols, g + ".Q2c");
    return p;
  }
  const std::string g = f + ".discrete";
  const json& c = j["discrete"];
  require_keys(c, g, {"Phi", "Gamma", "Gamma_w", "C", "Q", "Q1", "Q2", "period_us"});
  p.kind = PlantSpec::Kind::kDiscrete;
  DiscreteModel& m = p.discrete;
  m.phi = matrix(c, g, "Phi", false);
  const std::size_t n = m.phi.rows;
  shape(m.phi, n, n, g + ".Phi");
  m.gamma = matrix(c, g, "Gamma", false);
  shape(m.gamma, n, m.gamma.cols, g + ".Gamma");
  m.gamma_w = matrix(c, g, "Gamma_w", true);
  if (m.gamma_w.rows != 0) shape(m.gamma_w, n, m.gamma_w.cols, g + ".Gamma_w");
  m.c = matrix(c, g, "C", false);
  shape(m.c, m.c.rows, n, g + ".C");
  dimension_limits(n, m.gamma.cols, m.c.rows, m.gamma_w.cols, g);
  m.q = matrix(c, g, "Q", false);
  psd(m.q, n, g + ".Q");
  m.q1 = matrix(c, g, "Q1", true);
  psd(m.q1, n, g + ".Q1");
  m.q2 = matrix(c, g, "Q2", true);
  psd(m.q2, m.gamma.cols, g + ".Q2");
  m.period = from_us(integer_in(c, g, "period_us", 1, 3'600'000'000));
  return p;
}

}  // namespace oneshot::engine::detail
