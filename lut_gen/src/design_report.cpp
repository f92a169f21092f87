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

nlohmann::json design_json(const PlantDescription& plant, const DesignResult& d) {
  nlohmann::json j;
  j["plant"] = plant.name;
  j["source"] = plant.source;
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
  j["riccati_S"] = matrix_json(d.riccati);
  j["closed_loop_spectral_radius"] = d.closed_loop_radius;
  j["kalman_prior_P"] = matrix_json(d.kalman_prior);
  j["kalman_posterior_P"] = matrix_json(d.kalman_posterior);
  j["estimator_spectral_radius"] = d.estimator_radius;
  j["setpoint_tracking"] = d.tracking;
  j["Nx"] = matrix_json(d.nx);
  j["Nu"] = matrix_json(d.nu);
  j["deadbeat_available"] = d.deadbeat;
  j["deadbeat_gain"] = flat_json(d.deadbeat_gain);
  j["P0"] = matrix_json(d.p0);
  j["Q_constant"] = matrix_json(d.q_constant);
  j["R"] = matrix_json(d.r);
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
  out << "Design of '" << plant.name << "' (" << plant.source << "), h = " << d.period_s * 1e3 << " ms\n";
  out << "Discrete model (exact zero-order hold):\n";
  print_matrix(out, "Phi(h)", d.phi_h);
  print_matrix(out, "Gamma(h)", d.gamma_h);
  print_matrix(out, "Qd(h)", d.qd_h);
  out << "Sampled cost of J = integral(x'Q1c x + u'Q2c u) dt:\n";
  print_matrix(out, "Q1", d.q1);
  print_matrix(out, "Q12", d.q12);
  print_matrix(out, "Q2", d.q2);
  out << "LQR (u = -L x):\n";
  print_matrix(out, "L", d.l);
  out << "  closed-loop spectral radius = " << d.closed_loop_radius << "\n";
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
    out << "Set-point feed-forward: not available (needs as many outputs as inputs and a unique equilibrium)\n";
  }
  if (d.deadbeat) {
    print_matrix(out, "K deadbeat", d.deadbeat_gain);
  } else {
    out << "Deadbeat observer: not available (needs one output and an observable pair)\n";
  }
}

}  // namespace oneshot::design
