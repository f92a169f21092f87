/// @file design_report.cpp
/// @brief JSON and text forms of the design.
#include "oneshot/design/design_report.hpp"

#include <cstdio>
#include <string>

namespace oneshot::design {

nlohmann::json matrix_json(const DenseMatrix& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < m.rows; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t j = 0; j < m.cols; ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json flat_json(const DenseMatrix& m) { return nlohmann::json(m.values); }

namespace {
/// j[available_key] and, when it is false, j[<what>_unavailable_reason].
void put_availability(nlohmann::json& j, const std::string& what, const std::string& available_key, bool available,
                      const std::string& reason) {
  j[available_key] = available;
  if (!available) j[what + "_unavailable_reason"] = reason;
}
}  // namespace

nlohmann::json design_json(const PlantDescription& plant, const DesignResult& d) {
  nlohmann::json j;
  j["plant"] = plant.name;
  j["source"] = plant.source;
  j["form"] = to_string(plant.form);
  j["states"] = plant.states;
  j["h_s"] = d.period_s;
  j["Phi_h"] = matrix_json(d.phi_h);
  j["Gamma_h"] = flat_json(d.gamma_h);
  j["L"] = flat_json(d.l);
  j["kalman_gain"] = flat_json(d.kalman_gain);
  j["Qd_h"] = matrix_json(d.qd_h);
  j["Qc"] = matrix_json(d.qc);
  j["Q1"] = matrix_json(d.q1);
  j["Q12"] = matrix_json(d.q12);
  j["Q2"] = matrix_json(d.q2);
  put_availability(j, "lqr", "lqr_available", d.lqr_available, d.lqr_unavailable_reason);
  j["riccati_S"] = matrix_json(d.riccati);
  j["lqr_riccati_residual"] = d.lqr_residual;
  j["closed_loop_spectral_radius"] = d.closed_loop_radius;
  j["exogenous_states"] = d.exogenous_states;
  j["exogenous_spectral_radius"] = d.exogenous_radius;
  j["kalman_prior_P"] = matrix_json(d.kalman_prior);
  j["kalman_posterior_P"] = matrix_json(d.kalman_posterior);
  j["estimator_spectral_radius"] = d.estimator_radius;
  j["kalman_riccati_residual"] = d.kalman_residual;
  put_availability(j, "setpoint_tracking", "setpoint_tracking", d.tracking, d.tracking_unavailable_reason);
  nlohmann::json tracked = nlohmann::json::array();
  for (std::size_t o : d.tracked_outputs) tracked.push_back(plant.outputs[o]);
  j["tracked_outputs"] = tracked;
  j["Nx"] = matrix_json(d.nx);
  j["Nu"] = matrix_json(d.nu);
  put_availability(j, "deadbeat", "deadbeat_available", d.deadbeat, d.deadbeat_unavailable_reason);
  j["deadbeat_gain"] = flat_json(d.deadbeat_gain);
  j["deadbeat_residual"] = d.deadbeat_residual;
  j["P0"] = matrix_json(d.p0);
  j["Q_constant"] = matrix_json(d.q_constant);
  j["R"] = matrix_json(d.r);
  if (plant.q() != 0) {
    nlohmann::json dist;
    dist["names"] = plant.disturbances;
    dist["B_w"] = matrix_json(plant.b_w);
    dist["input"] = plant.continuous() ? "continuous" : "per step";
    dist["Gamma_w_h"] = matrix_json(d.gamma_w_h);
    if (plant.disturbance_intensity.rows != 0) dist["intensity"] = matrix_json(plant.disturbance_intensity);
    if (plant.disturbance_covariance_per_period.rows != 0) {
      dist["covariance_per_period"] = matrix_json(plant.disturbance_covariance_per_period);
    }
    if (plant.c_bar.rows != 0) dist["C_bar"] = matrix_json(plant.c_bar);
    j["disturbance"] = dist;  // absent without disturbance inputs (outputs hold no null)
  }
  j["u_min"] = d.u_min;
  j["u_max"] = d.u_max;
  return j;
}

namespace {
void print_matrix(std::ostream& out, const char* name, const DenseMatrix& m) {
  out << "  " << name << " =";
  for (std::size_t i = 0; i < m.rows; ++i) {
    out << (i == 0 ? " [" : "\n" + std::string(5 + std::string(name).size(), ' ') + " ");
    for (std::size_t j = 0; j < m.cols; ++j) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%s%13.6e", j == 0 ? "" : " ", m(i, j));
      out << buf;
    }
  }
  out << " ]\n";
}
}  // namespace

void print_design(std::ostream& out, const PlantDescription& plant, const DesignResult& d) {
  out << "Design of '" << plant.name << "' (" << plant.source << ", " << to_string(plant.form)
      << " form), h = " << d.period_s * 1e3 << " ms\n";
  out << (plant.continuous() ? "Discrete model (exact zero-order hold):\n" : "Discrete model:\n");
  print_matrix(out, "Phi(h)", d.phi_h);
  print_matrix(out, "Gamma(h)", d.gamma_h);
  print_matrix(out, "Qd(h)", d.qd_h);
  if (plant.q() != 0) print_matrix(out, "Gamma_w(h)", d.gamma_w_h);
  out << (plant.cost_form == CostForm::kContinuous ? "Sampled cost of J = integral(x'Q1c x + u'Q2c u) dt:\n"
                                                    : "Cost weights per step:\n");
  print_matrix(out, "Q1", d.q1);
  print_matrix(out, "Q12", d.q12);
  print_matrix(out, "Q2", d.q2);
  out << "LQR (u = -L x):\n";
  if (d.lqr_available) {
    print_matrix(out, "L", d.l);
    out << "  closed-loop spectral radius = " << d.closed_loop_radius << "\n";
    if (d.exogenous_states != 0) {
      out << "  (" << d.exogenous_states << " exogenous disturbance states cancelled at the input, spectral radius "
          << d.exogenous_radius << ")\n";
    }
  } else {
    out << "  not designed: " << d.lqr_unavailable_reason << "\n";
  }
  out << "Steady-state Kalman filter:\n";
  print_matrix(out, "K", d.kalman_gain);
  print_matrix(out, "P prior", d.kalman_prior);
  print_matrix(out, "P posterior", d.kalman_posterior);
  out << "  estimator spectral radius = " << d.estimator_radius << "\n";
  if (d.tracking) {
    out << "Set-point feed-forward (x_ref = Nx r, u_ref = Nu r):\n";
    print_matrix(out, "Nx", d.nx);
    print_matrix(out, "Nu", d.nu);
  } else {
    out << "Set-point feed-forward: not available: " << d.tracking_unavailable_reason << "\n";
  }
  if (d.deadbeat) {
    print_matrix(out, "K deadbeat", d.deadbeat_gain);
  } else {
    out << "Deadbeat observer: not available: " << d.deadbeat_unavailable_reason << "\n";
  }
}

}  // namespace oneshot::design
