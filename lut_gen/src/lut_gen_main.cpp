/// @file lut_gen_main.cpp
/// @brief lut_gen: build-time generator of the table header and lut_report.json.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/design_report.hpp"
#include "oneshot/design/fixed_formats.hpp"
#include "oneshot/design/header_emitter.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"
#include "oneshot/host/file_io.hpp"
#include "oneshot/host/strict_json.hpp"

namespace {

template <typename S>
nlohmann::json table_json(const oneshot::design::TableData<S>& t, const oneshot::design::TableAccuracy& a) {
  nlohmann::json j;
  j["bytes"] = t.bytes();
  j["value_bytes"] = sizeof(S) * t.values.size();
  j["residual_bytes"] = sizeof(S) * t.residual_coefficients.size();
  j["index_bytes"] = t.bytes() - sizeof(S) * (t.values.size() + t.residual_coefficients.size());
  j["entries"] = t.entry_time_us.size();
  j["slots"] = t.slots;
  j["levels"] = t.radix.size();
  j["radix"] = t.radix;
  j["entry_time_us"] = t.entry_time_us;
  j["granularity_us"] = t.granularity_us;
  j["range_us"] = t.range_us;
  j["max_abs_error"] = a.max_abs_error;
  j["phi_max_abs_error"] = a.phi_abs;
  j["gamma_max_abs_error"] = a.gamma_abs;
  j["qd_max_abs_error"] = a.qd_abs;
  j["phi_max_rel_error"] = a.phi_rel;
  j["gamma_max_rel_error"] = a.gamma_rel;
  j["qd_max_rel_error"] = a.qd_rel;
  j["points_compared"] = a.points;
  return j;
}

/// Atomic, checked write (temporary file, fsync, rename): the build never sees half a header.
void write_file(const std::string& path, const std::string& text) { oneshot::host::write_file_atomic(path, text); }

}  // namespace

int main(int argc, char** argv) {
  namespace d = oneshot::design;
  CLI::App app{"lut_gen: design step and Phi/Gamma/Qd table generator (run by the build)"};
  std::string plant_path;
  std::string header_path;
  std::string report_path;
  app.add_option("--plant", plant_path, "plant description JSON (default: the built-in reference board)");
  app.add_option("--header", header_path, "generated C++ header to write")->required();
  app.add_option("--report", report_path, "lut_report.json to write")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    const d::PlantDescription plant = plant_path.empty() ? d::reference_plant() : d::load_plant_file(plant_path);
    const d::DesignResult design = d::synthesize(plant);
    const d::PlantPatterns patterns = d::analyse_structure(plant, design);
    const auto table_f = d::build_table<float>(plant, design, patterns);
    const auto table_d = d::build_table<double>(plant, design, patterns);
    const auto acc_f = d::measure_accuracy(table_f, plant, design);
    const auto acc_d = d::measure_accuracy(table_d, plant, design);
    // Fixed point is optional: a plant whose numbers do not fit gets float/double only.
    std::unique_ptr<d::FixedFormats> formats;
    std::unique_ptr<d::TableData<oneshot::BlockFixedStorage>> table_q;
    std::string fixed_reason;
    try {
      formats = std::make_unique<d::FixedFormats>(d::choose_fixed_formats(plant, design));
      table_q = std::make_unique<d::TableData<oneshot::BlockFixedStorage>>(
          d::build_table<oneshot::BlockFixedStorage>(plant, design, patterns));
    } catch (const d::DesignError& e) {
      fixed_reason = e.what();
      formats.reset();
      table_q.reset();
      std::cerr << "lut_gen: warning: no fixed-point build for this plant: " << fixed_reason << "\n";
    }
    write_file(header_path, d::emit_header(plant, design, patterns, table_f, table_d, formats.get(), table_q.get(),
                                           fixed_reason, "lut_gen"));
    nlohmann::json report = table_json(table_f, acc_f);  // top level: the float table the MCU uses
    report["generated_by"] = "lut_gen";
    report["plant"] = plant.name;
    report["source"] = plant.source;
    report["max_bytes"] = plant.table_max_bytes;
    report["formats"]["float"] = table_json(table_f, acc_f);
    report["formats"]["double"] = table_json(table_d, acc_d);
    nlohmann::json fixed;
    fixed["available"] = formats != nullptr;
    if (!formats) fixed["reason"] = fixed_reason;
    if (formats) {
    fixed["bytes"] = table_q->bytes();
    fixed["entries"] = table_q->entry_time_us.size();
    fixed["slots"] = table_q->slots;
    fixed["levels"] = table_q->radix.size();
    fixed["radix"] = table_q->radix;
    fixed["granularity_us"] = table_q->granularity_us;
    fixed["range_us"] = table_q->range_us;
    fixed["max_quantization_error"] = table_q->quantization_abs;
    fixed["max_quantization_error_relative"] = table_q->quantization_rel;
    fixed["value_frac"] = table_q->value_frac;
    fixed["residual_frac"] = table_q->residual_frac;
    for (const d::QuantityFormat& q : formats->table) {
      fixed["quantity_formats"][q.name] = {{"bits", q.format.bits}, {"frac", q.format.frac}, {"range", q.range},
                                           {"max_value", q.format.max_value()}, {"resolution", q.format.resolution()},
                                           {"rationale", q.rationale}};
    }
    fixed["qd_scale_shift"] = formats->qd_scale_shift;
    }
    report["formats"]["fixed"] = fixed;
    report["design"] = d::design_json(plant, design);
    write_file(report_path, oneshot::host::dump_finite(report) + "\n");
    std::cout << "lut_gen: " << plant.name << ": float table " << table_f.bytes() << " bytes (" << table_f.radix.size()
              << " levels, " << table_f.entry_time_us.size() << " entries x " << static_cast<int>(table_f.slots)
              << " slots), max abs error " << acc_f.max_abs_error;
    if (table_q) {
      std::cout << "; fixed table " << table_q->bytes() << " bytes, max quantization error " << table_q->quantization_abs;
    }
    std::cout << "\n";
  } catch (const std::exception& e) {
    std::cerr << "lut_gen: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
