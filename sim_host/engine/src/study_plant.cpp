/// @file study_plant.cpp
/// @brief The plant section of a study file (see study_parse_detail.hpp).
#include <array>
#include <cmath>
#include <vector>

#include "oneshot/design/plant_description.hpp"
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

/// Both plant forms share one shape: state matrix F (n×n), input matrix G (n×m), optional
/// disturbance matrix G_w (n×w), output matrix C (p×n), noise covariance (n×n, PSD) and
/// optional PSD weights on the state (n×n) and the input (m×m), read from `keys` in that order.
void linear_model(const json& c, const std::string& g, const std::array<const char*, 7>& keys,
                  const std::array<DenseMatrix*, 7>& out) {
  const auto field = [&](std::size_t k) { return g + "." + keys[k]; };
  DenseMatrix& f = *out[0] = matrix(c, g, keys[0], false);
  const std::size_t n = f.rows;
  shape(f, n, n, field(0));
  DenseMatrix& in = *out[1] = matrix(c, g, keys[1], false);
  shape(in, n, in.cols, field(1));
  DenseMatrix& dist = *out[2] = matrix(c, g, keys[2], true);
  if (dist.rows != 0) shape(dist, n, dist.cols, field(2));
  DenseMatrix& out_c = *out[3] = matrix(c, g, keys[3], false);
  shape(out_c, out_c.rows, n, field(3));
  // Named by the matrix whose size is past the limit: F (n), then G (m), C (p), G_w (w).
  const std::string limited = n > kMaxStates ? field(0) : in.cols > kMaxInputs ? field(1) : out_c.rows > kMaxOutputs ? field(3) : field(2);
  dimension_limits(n, in.cols, out_c.rows, dist.cols, limited);
  *out[4] = matrix(c, g, keys[4], false);
  psd(*out[4], n, field(4));
  *out[5] = matrix(c, g, keys[5], true);
  psd(*out[5], n, field(5));
  *out[6] = matrix(c, g, keys[6], true);
  psd(*out[6], in.cols, field(6));
}

/// The plant-file field a design error names, as the inline key (noise.* and cost.* are flat inline;
/// a discrete plant's per-step covariance is Q, its disturbance input Gamma_w).
std::string inline_key(const std::string& plant_file_field) {
  if (plant_file_field == "noise.process_intensity") return "Q_c";
  if (plant_file_field == "noise.process_covariance_per_period") return "Q";
  if (plant_file_field == "B_w") return "Gamma_w";
  if (plant_file_field.rfind("noise.", 0) == 0 || plant_file_field.rfind("cost.", 0) == 0) {
    return plant_file_field.substr(plant_file_field.find('.') + 1);
  }
  return plant_file_field;
}

/// The keys an inline continuous plant carries for the design step, with the plant file's names and units.
constexpr std::array<const char*, 10> kDesignKeys = {"period_us", "measurement_covariance", "name",     "states", "inputs",
                                                   "outputs",   "tracked_outputs",        "actuator", "board",  "table"};

/// The design keys of an inline discrete plant (its period_us is the sampling period h).
constexpr std::array<const char*, 10> kDiscreteDesignKeys = {"measurement_covariance", "Q1c",     "Q2c",   "name",
                                                             "states",  "inputs", "outputs", "tracked_outputs",
                                                             "actuator", "board"};

/// What differs between the inline forms read for the design step.
struct InlineForm {
  const char* form;                       ///< The plant file's form: "continuous" or "discrete".
  std::array<const char*, 2> required;    ///< Keys required beside the design keys (nullptr: none).
  const char* missing_why;                ///< Why a required key is needed (the refusal's parenthesis).
  const char* disturbance;                ///< The inline disturbance input's key (refused: B_w, Gamma_w).
  bool refuses_discrete_cost;             ///< Q1, Q2 refused (a discrete plant's cost is then Q1c, Q2c).
  std::array<const char*, 3> model;       ///< The model matrices copied as they are (A, B, C or Phi, Gamma, C).
  const char* noise_key;                  ///< The inline noise key (Q_c, Q).
  const char* noise_field;                ///< Its plant-file field under noise.
};

/// An inline continuous plant: A, B, C, Q_c as the intensity; period_us and measurement_covariance required.
constexpr InlineForm kContinuousForm = {
    "continuous", {"period_us", "measurement_covariance"},
    "(an inline plant with design keys needs period_us and measurement_covariance)", "B_w", false, {"A", "B", "C"},
    "Q_c", "process_intensity"};

/// An inline discrete plant: Phi, Gamma, C, Q per step (its period_us is required anyway); the
/// cost only as Q1c, Q2c.
constexpr InlineForm kDiscreteForm = {
    "discrete", {"measurement_covariance", nullptr}, "(an inline discrete plant with design keys needs it)", "Gamma_w",
    true, {"Phi", "Gamma", "C"}, "Q", "process_covariance_per_period"};

/// The plant-file description of an inline plant `c` of form `form` at field `g` with the design
/// keys: the same JSON a plant file would hold (the model matrices, period_us, names,
/// tracked_outputs, cost {Q1c, Q2c}, noise {the form's noise field, measurement_covariance},
/// actuator or board, table), parsed by the plant-file parser, its errors naming the inline key. A
/// discrete one is read as its exact continuous equivalent (d2c) when it has Q1c/Q2c or a board.
/// `disturbance_rows` and `outputs` are the rows of the model's disturbance input and of C.
std::shared_ptr<const design::PlantDescription> inline_plant_design(const json& c, const std::string& g,
                                                                    const InlineForm& form, std::size_t disturbance_rows,
                                                                    std::size_t outputs) {
  for (const char* k : form.required) {
    if (k != nullptr && !c.contains(k)) throw InputError("field '" + g + "." + k + "': missing " + form.missing_why);
  }
  if (disturbance_rows != 0) {
    throw InputError("field '" + g + "." + form.disturbance + "': the design step takes no disturbance input in an inline "
                     "plant (give a plant file with its disturbance noise)");
  }
  if (form.refuses_discrete_cost) {
    for (const char* k : {"Q1", "Q2"})
      if (c.contains(k)) {
        throw InputError("field '" + g + "." + k + "': with the design keys the cost is the continuous plant's: give Q1c "
                         "and Q2c (the design is then the same as for the continuous equivalent)");
      }
  }
  static_cast<void>(integer_in(c, g, "period_us", 1, 60'000'000));
  const DenseMatrix r = matrix(c, g, "measurement_covariance", false);
  psd(r, outputs, g + ".measurement_covariance");
  json f = json::object();
  f["name"] = c.contains("name") ? c["name"] : json("inline");
  f["form"] = form.form;
  for (const char* k : form.model)
    if (c.contains(k)) f[k] = c[k];
  for (const char* k : {"period_us", "states", "inputs", "outputs", "tracked_outputs", "actuator", "board", "table"})
    if (c.contains(k)) f[k] = c[k];  // table: continuous only (the discrete keys refuse it first)
  for (const char* k : {"Q1c", "Q2c"})
    if (c.contains(k)) f["cost"][k] = c[k];
  f["noise"] = {{form.noise_field, c[form.noise_key]}, {"measurement_covariance", c["measurement_covariance"]}};
  try {
    return std::make_shared<const design::PlantDescription>(design::parse_plant(f.dump(), g));
  } catch (const design::PlantError& e) {  // the design parser's field, renamed to the inline key
    if (e.field().empty()) throw InputError("field '" + g + "': " + e.what());
    throw InputError("field '" + g + "." + inline_key(e.field()) + "': " + e.reason());
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
    require_keys(c, g, {"A", "B", "B_w", "C", "Q_c", "Q1c", "Q2c", "period_us", "measurement_covariance", "name", "states",
                        "inputs", "outputs", "tracked_outputs", "actuator", "board", "table"});
    p.kind = PlantSpec::Kind::kContinuous;
    ContinuousModel& m = p.continuous;
    linear_model(c, g, {"A", "B", "B_w", "C", "Q_c", "Q1c", "Q2c"}, {&m.a, &m.b, &m.bw, &m.c, &m.qc, &m.q1c, &m.q2c});
    bool designed = false;
    for (const char* k : kDesignKeys) designed = designed || c.contains(k);
    if (designed) p.design = inline_plant_design(c, g, kContinuousForm, m.bw.rows, m.c.rows);
    return p;
  }
  const std::string g = f + ".discrete";
  const json& c = j["discrete"];
  require_keys(c, g, {"Phi", "Gamma", "Gamma_w", "C", "Q", "Q1", "Q2", "period_us", "measurement_covariance", "Q1c", "Q2c",
                      "name", "states", "inputs", "outputs", "tracked_outputs", "actuator", "board"});
  p.kind = PlantSpec::Kind::kDiscrete;
  DiscreteModel& m = p.discrete;
  linear_model(c, g, {"Phi", "Gamma", "Gamma_w", "C", "Q", "Q1", "Q2"}, {&m.phi, &m.gamma, &m.gamma_w, &m.c, &m.q, &m.q1, &m.q2});
  m.period = from_us(integer_in(c, g, "period_us", 1, 3'600'000'000));
  bool designed = false;
  for (const char* k : kDiscreteDesignKeys) designed = designed || c.contains(k);
  if (designed) p.design = inline_plant_design(c, g, kDiscreteForm, m.gamma_w.rows, m.c.rows);
  return p;
}

}  // namespace oneshot::engine::detail
