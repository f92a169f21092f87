/// @file study_plant_map.cpp
/// @brief The plant of a study file mapped onto the ncs loop (see study_plant_map.hpp).
#include "study_plant_map.hpp"

#include <cstddef>
#include <exception>
#include <filesystem>
#include <utility>

#include "ncs_model.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_fields.hpp"

namespace oneshot::study {
namespace {

/// The ncs context of an inline plant (continuous, or discrete read as its exact continuous
/// equivalent): a shape the loop runs (ncs::kNcsShapesText, any C), the design keys, then the
/// same design step as a plant file; refusals name the key under `g`.
std::shared_ptr<const ncs::Context> inline_context(const engine::PlantSpec& plant, const std::string& source) {
  const bool discrete = plant.kind == engine::PlantSpec::Kind::kDiscrete;
  const engine::DenseMatrix& a = discrete ? plant.discrete.phi : plant.continuous.a;
  const engine::DenseMatrix& b = discrete ? plant.discrete.gamma : plant.continuous.b;
  const engine::DenseMatrix& c = discrete ? plant.discrete.c : plant.continuous.c;
  const std::string g = discrete ? "plant.discrete" : "plant.continuous";
  const std::string runs = std::string("study ncs runs ") + ncs::kNcsShapesText;
  if (!ncs::ncs_shape_runs(a.rows, b.cols, c.rows)) {
    // Name the matrix whose size is off: A (Φ) for n, else B (Γ) for m, else C for p.
    const char* key = a.rows > ncs::kMaxNcsStates ? (discrete ? ".Phi" : ".A")
                      : b.cols > ncs::kMaxNcsInputs ? (discrete ? ".Gamma" : ".B")
                                                    : ".C";
    refuse(g + key, "n = " + std::to_string(a.rows) + ", m = " + std::to_string(b.cols) + ", p = " + std::to_string(c.rows) + "; " + runs);
  }
  if (!plant.design) {
    refuse(g + ".measurement_covariance",
           discrete ? "missing: the ncs design needs the plant file's keys inline (measurement_covariance, Q1c, Q2c, board); "
                      "the plant then runs as its exact continuous equivalent"
                    : "missing: the ncs design needs the plant file's keys inline (period_us, measurement_covariance, Q1c, "
                      "Q2c, board)");
  }
  if (plant.design->cost_form == design::CostForm::kNone) refuse(g + ".Q1c", "missing: the ncs loop's LQR gain needs Q1c and Q2c");
  if (!plant.design->has_board) {
    refuse(g + ".board", "missing: the ncs loop's converter models (PWM actuator, ADC) need a board (an actuator range alone "
                         "does not run)");
  }
  design::PlantDescription d = *plant.design;
  d.source = source + ": " + g;
  try {
    return ncs::Context::from(std::move(d));
  } catch (const std::exception& e) {
    refuse(g, e.what());
  }
}

}  // namespace

std::string plant_file_path(const engine::StudyFile& file) {
  const std::filesystem::path p(file.plant.file);
  if (p.is_absolute()) return p.string();
  return (std::filesystem::path(file.source).parent_path() / p).lexically_normal().string();
}

NcsPlant map_ncs_plant(const engine::StudyFile& file) {
  NcsPlant out;
  out.covariance_field = "plant.file";
  if (file.plant.kind != engine::PlantSpec::Kind::kFile) {
    out.ctx = inline_context(file.plant, file.source);
    out.covariance_field = file.plant.kind == engine::PlantSpec::Kind::kDiscrete ? "plant.discrete.measurement_covariance"
                                                                                  : "plant.continuous.measurement_covariance";
  } else {
    out.plant_path = plant_file_path(file);
    try {
      out.ctx = ncs::Context::load(out.plant_path);
    } catch (const std::exception& e) {
      refuse("plant.file", e.what());
    }
  }
  return out;
}

}  // namespace oneshot::study
