/// @file pil_cleanup_test.cpp
/// @brief Killing `oneshot-sim pil` ends its QEMU and leaves no temporary files, whatever
///        the signal (SIGTERM, SIGINT from a terminal, SIGKILL).
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <chrono>
#include <filesystem>
#include <thread>
#include <unistd.h>

#include "support/run_command.hpp"

namespace oneshot {
namespace {

namespace fs = std::filesystem;

/// Processes carrying `marker` in their environment, other than `except`.
std::vector<int> others_with(const std::string& marker, int except) {
  std::vector<int> p = test::processes_with_environment(marker);
  p.erase(std::remove(p.begin(), p.end(), except), p.end());
  return p;
}

void kill_pil_and_check(int sig) {
  const fs::path tmp = fs::temp_directory_path() / ("oneshot_pil_kill_" + std::to_string(::getpid()) + "_" +
                                                    std::to_string(sig));
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  // QEMU inherits the environment: a TMPDIR of its own marks this run's processes and
  // collects whatever temporary files they would leave.
  const std::string marker = "TMPDIR=" + tmp.string();
  test::CommandOptions options;
  options.env = {marker};
  test::BackgroundCommand pil({ONESHOT_SIM_PATH, "pil", "--duration", "3600", "--no-plots", "--out", (tmp / "out").string()},
                              options);
  ASSERT_TRUE(test::eventually([&] { return !others_with(marker, pil.pid()).empty(); }, 30'000)) << "QEMU never started";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // well into the run
  ::kill(pil.pid(), sig);
  const auto r = pil.wait(10'000);
  EXPECT_EQ(r.signal, sig) << r.output;
  EXPECT_TRUE(test::eventually([&] { return others_with(marker, pil.pid()).empty(); }, 5'000))
      << "QEMU still running after the harness was killed";
  std::vector<std::string> left;
  for (const auto& e : fs::recursive_directory_iterator(tmp)) left.push_back(e.path().string());
  EXPECT_TRUE(left.empty()) << left.front();
  fs::remove_all(tmp);
}

TEST(PilCleanup, SigtermEndsQemuAndLeavesNothing) { kill_pil_and_check(SIGTERM); }
TEST(PilCleanup, SigintEndsQemuAndLeavesNothing) { kill_pil_and_check(SIGINT); }
TEST(PilCleanup, SigkillEndsQemuAndLeavesNothing) { kill_pil_and_check(SIGKILL); }

}  // namespace
}  // namespace oneshot
