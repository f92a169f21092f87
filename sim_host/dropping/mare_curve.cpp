/// @file mare_curve.cpp
/// @brief E2/E3: tr P̄(λ) and K̄(λ) of the MARE on (λ_sys, 1], with λ_sys, the bisection's
///        λc and the certificate's verdict at every point (see experiments.hpp).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "experiments.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "study_format.hpp"

namespace oneshot::dropping {

nlohmann::json run_mare_curve(const DroppingPlant& plant, const StudyOptions& opt, const LambdaCOptions& lc) {
  util::make_directory(opt.out_dir);
  const MareModel<kN, kP> m = plant.mare();
  const LambdaCBracket b = lambda_c_bisection(m, plant.lambda_sys, lc.bracket_width, lc.mare);
  if (!b.hi_converges) throw std::runtime_error("the MARE diverges at lambda = 1: no curve to draw");
  // Points: λc_hi + δ with δ log-spaced from 1e-4 to 1 − λc_hi, and the zoom [0.34, 0.42] in 0.002 steps.
  std::vector<double> lambdas;
  const int n_log = 48;
  for (int i = 0; i <= n_log; ++i) {
    const double e = -4 + (std::log10(1 - b.hi) + 4) * i / n_log;
    lambdas.push_back(std::min(1.0, b.hi + std::pow(10.0, e)));
  }
  for (int i = 0; i <= 40; ++i) lambdas.push_back(0.34 + 0.002 * i);
  std::sort(lambdas.begin(), lambdas.end());
  lambdas.erase(std::unique(lambdas.begin(), lambdas.end()), lambdas.end());

  struct Point {
    MareOutcome o;
    Matrix<double, kN, kP> k;
    Certificate c;
  };
  std::vector<Point> pts(lambdas.size());
  util::parallel_for(lambdas.size(), util::worker_count(opt.threads), nullptr, [&](std::size_t i) {
    Matrix<double, kN, kN> p;
    pts[i].o = mare_fixed_point(m, lambdas[i], p, lc.mare);
    pts[i].k = pts[i].o.converged ? mare_gain(m, p) : Matrix<double, kN, kP>{} * std::numeric_limits<double>::quiet_NaN();
    pts[i].c = certify(m, lambdas[i], lc.certificate_eps_rel, lc.mare);
  });
  std::vector<std::vector<double>> csv;
  nlohmann::json rows = nlohmann::json::array();
  std::size_t agree = 0;
  for (std::size_t i = 0; i < lambdas.size(); ++i) {
    const Point& p = pts[i];
    const double tr = p.o.converged ? p.o.trace : std::numeric_limits<double>::quiet_NaN();
    // The CSV (and its plots) holds the converged points only; the JSON lists every point.
    if (p.o.converged) {
      csv.push_back({lambdas[i], 1.0, tr, static_cast<double>(p.o.iterations), p.k(0, 0), p.k(1, 0), p.k(2, 0),
                     p.c.certified ? 1.0 : 0.0, (lambdas[i] - 0.5 * (b.lo + b.hi)) * tr});
    }
    if (p.o.converged == p.c.certified) ++agree;
    rows.push_back({{"lambda", lambdas[i]},
                    {"converged", p.o.converged},
                    {"iterations", p.o.iterations},
                    {"trace_p", num(tr)},
                    {"K", {num(p.k(0, 0)), num(p.k(1, 0)), num(p.k(2, 0))}},
                    {"certified", p.c.certified},
                    {"certificate_reason", p.c.reason}});
  }
  const std::string dir = opt.out_dir;
  util::write_csv((std::filesystem::path(dir) / "mare_curve.csv").string(),
                 {"lambda", "converged", "trace_p", "iterations", "K1", "K2", "K3", "certified", "trace_times_distance"}, csv);
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1200, 500) << "set output 'mare_curve.png'\n"
         "set datafile separator ','\nset datafile missing 'nan'\nset multiplot layout 1,2\nset grid\n"
         "set logscale y\nset format y '10^{%L}'\nset xlabel 'lambda'\nset ylabel 'tr Pbar'\n"
         "set arrow 1 from " << plant.lambda_sys << ", graph 0 to " << plant.lambda_sys
      << ", graph 1 nohead dt 2 lc rgb 'black'\nset arrow 2 from " << b.hi << ", graph 0 to " << b.hi
      << ", graph 1 nohead dt 3 lc rgb 'red'\n"
         "set title sprintf('E2: MARE tr Pbar(lambda); lambda_sys = %.5f (black), lambda_c <= %.5f (red)', "
      << plant.lambda_sys << ", " << b.hi << ")\nset xrange [" << plant.lambda_sys << ":1]\n"
         "plot 'mare_curve.csv' skip 1 using 1:3 with linespoints pt 7 ps 0.4 title 'MARE fixed point', "
         "'' skip 1 using 1:($8==1?$3:1/0) with points pt 6 ps 1.2 lc rgb 'dark-green' title 'LMI certificate holds'\n"
         "set title 'zoom [0.34, 0.42]'\nset xrange [0.34:0.42]\nreplot\nunset multiplot\n";
    util::run_gnuplot(dir, "mare_curve.gp", g.str());
    std::ostringstream k;
    k << util::gnuplot_png_terminal(900, 500) << "set output 'mare_gain.png'\n"
         "set datafile separator ','\nset datafile missing 'nan'\nset grid\nset xlabel 'lambda'\nset ylabel 'Kbar'\n"
         "set title 'E3: Kbar(lambda) = M C^T (C M C^T + R)^-1 at the MARE fixed point'\nset xrange ["
      << b.hi << ":1]\nplot for [c=5:7] 'mare_curve.csv' skip 1 using 1:c with lines lw 2 title columnhead(c)\n";
    util::run_gnuplot(dir, "mare_gain.gp", k.str());
  }
  nlohmann::json j;
  j["experiment"] = "mare";
  j["lambda_sys"] = plant.lambda_sys;
  j["lambda_c_bracket"] = {b.lo, b.hi};
  j["points"] = rows;
  j["certificate_agrees_with_iteration"] = agree;
  j["point_count"] = lambdas.size();
  j["files"] = {"mare_curve.csv", "mare_curve.png", "mare_gain.png"};
  return j;
}

}  // namespace oneshot::dropping
