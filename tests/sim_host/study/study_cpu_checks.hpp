/// @file study_cpu_checks.hpp
/// @brief The checks the study tests make of a controller job on a CPU, whichever loop runs it
///        (arrival-driven or one-shot): every observed response within the analysis' bounds,
///        and a lone constant-time job equal to the loop with that constant τ_c.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <utility>

#include <nlohmann/json.hpp>

#include "ncs_cpu.hpp"
#include "ncs_loop.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study::test_support {

/// In `run` (study run's JSON) every approach of `approaches` ran `jobs` controller jobs (one
/// per period: none lost) whose responses lie in [BCRT, WCRT] of `c`, with no deadline miss and
/// none of the CPU's other tasks' either; I did not use the CPU. Prints the observed range.
inline void expect_controller_jobs_within_bounds(const nlohmann::json& run, const ncs::ControllerCpu& c,
                                                 std::initializer_list<const char*> approaches, double jobs,
                                                 const char* label) {
  for (const char* a : approaches) {
    const nlohmann::json& e = run.at("cpu").at(a);
    EXPECT_EQ(e.at("jobs").get<double>(), jobs) << label << " " << a;
    EXPECT_GE(e.at("min_us").get<double>(), static_cast<double>(c.bcrt.count()) * 1e-3) << label << " " << a;
    EXPECT_LE(e.at("max_us").get<double>(), static_cast<double>(c.wcrt.count()) * 1e-3) << label << " " << a;
    EXPECT_TRUE(e.at("within_bounds").get<bool>()) << label << " " << a;
    EXPECT_EQ(e.at("deadline_misses").get<double>(), 0) << label << " " << a;
    EXPECT_EQ(e.at("other_misses").get<double>(), 0) << label << " " << a;
    std::printf("%s %s: tau_c %.1f .. %.1f us (mean %.1f) within [%.1f, %.1f]\n", label, a, e.at("min_us").get<double>(),
                e.at("max_us").get<double>(), e.at("mean_us").get<double>(), e.at("bcrt_us").get<double>(),
                e.at("wcrt_us").get<double>());
  }
  EXPECT_EQ(run.at("cpu").at("I").at("jobs").get<double>(), 0);  // delay-free: not on the CPU
}

/// The example's controller job made a lone constant 2345 µs job (no background task, ISR or
/// switch) gives, on every approach, scenario and 3 seeds, the costs (1e-12), commands, late
/// commands and frames sent of the loop with τ_c constant 2345 µs, its response exactly that.
inline void expect_lone_constant_job_is_the_constant_delay(const StudyExample& example) {
  const auto lone = [](nlohmann::json& j) {
    j["cpus"][0].erase("tasks");
    j["cpus"][0].erase("isrs");
    j["cpus"][0]["context_switch_us"] = 0;
    j["nodes"][1]["job"] = {{"wcet_us", 2345}, {"bcet_us", 2345}, {"priority", 1}};
  };
  const NcsStudy on_cpu = example.study(lone, 3);
  NcsStudy constant = on_cpu;
  for (ncs::Scenario& x : constant.scenarios) {
    x.controller_cpu = nullptr;
    x.compute_us = std::make_pair(std::int64_t{2345}, std::int64_t{2345});
  }
  EXPECT_EQ(on_cpu.scenarios[0].controller_cpu->wcrt, engine::from_us(2345));
  EXPECT_EQ(on_cpu.scenarios[0].controller_cpu->bcrt, engine::from_us(2345));
  for (ncs::Approach a : on_cpu.approaches) {
    for (std::size_t k = 0; k < on_cpu.scenarios.size(); ++k) {
      for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const ncs::RunResult x = ncs::run(*on_cpu.ctx, a, on_cpu.scenarios[k], seed, ncs::RunOptions{});
        const ncs::RunResult y = ncs::run(*constant.ctx, a, constant.scenarios[k], seed, ncs::RunOptions{});
        EXPECT_NEAR(x.cost, y.cost, 1e-12 * std::fabs(y.cost)) << ncs::name(a) << " seed " << seed;
        EXPECT_EQ(x.commands, y.commands) << ncs::name(a);
        EXPECT_EQ(x.late, y.late) << ncs::name(a);
        EXPECT_EQ(x.sent, y.sent) << ncs::name(a);
        if (x.cpu.jobs > 0) {
          EXPECT_EQ(x.cpu.response_min, engine::from_us(2345));
          EXPECT_EQ(x.cpu.response_max, engine::from_us(2345));
        }
      }
    }
  }
}

}  // namespace oneshot::study::test_support
