/// @file host_util_test.cpp
/// @brief Host services: bounded reads, atomic writes, strict JSON, children without a shell,
///        enumeration name tables.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <limits>
#include <utility>
#include <sys/resource.h>
#include <unistd.h>

#include "oneshot/util/child_process.hpp"
#include "oneshot/util/enum_names.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/strict_json.hpp"
#include "support/temp_files.hpp"
#include "support/expect_error.hpp"

namespace oneshot::util {
namespace {

namespace fs = std::filesystem;

/// A fresh empty folder `name` (any characters) for one test.
std::string fresh_dir(const std::string& name) { return test::made_dir("oneshot_host_util", name); }

using test::message_of;

TEST(TempDir, RemovesItsFolderWithEverythingInItWhenItEnds) {
  const std::string dir = fresh_dir("scratch") + "/owned";
  fs::create_directories(dir + "/sub");
  std::ofstream(dir + "/sub/f.txt") << "x";
  {
    test::TempDir owner(dir);
    test::TempDir moved(std::move(owner));  // the moved-from one owns nothing
    EXPECT_EQ(owner.path(), "");
    EXPECT_EQ(moved.path(), dir);
    EXPECT_TRUE(fs::exists(dir + "/sub/f.txt"));
  }
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_TRUE(fs::exists(fs::path(dir).parent_path()));  // fresh_dir's own folder waits for the process end
}

TEST(PlotFiles, PngTerminalLineNamesSizeAndFont) {
  EXPECT_EQ(gnuplot_png_terminal(1100, 700), "set terminal pngcairo size 1100,700 font 'Sans,11' noenhanced\n");
  EXPECT_EQ(gnuplot_png_terminal(1500, 520, 10), "set terminal pngcairo size 1500,520 font 'Sans,10' noenhanced\n");
}

TEST(BoundedRead, DevZeroIsRefusedAtTheLimitInsteadOfFillingMemory) {
  const std::string m = message_of([] { read_text_file("/dev/zero", "scenario file", std::size_t{1} << 20); });
  EXPECT_NE(m.find("/dev/zero: longer than 1048576 bytes, the limit for a scenario file"), std::string::npos) << m;
}

TEST(BoundedRead, ADirectoryIsNamedAsOne) {
  const std::string dir = fresh_dir("dir");
  const std::string m = message_of([&] { read_text_file(dir, "scenario file"); });
  EXPECT_NE(m.find("is a directory, not a scenario file"), std::string::npos) << m;
}

TEST(BoundedRead, ReadsAFileWhole) {
  const std::string path = fresh_dir("read") + "/f.txt";
  std::ofstream(path) << "abc\ndef";
  EXPECT_EQ(read_text_file(path, "file"), "abc\ndef");
  EXPECT_NE(message_of([&] { read_text_file(path + ".missing", "file"); }).find("cannot read the file"), std::string::npos);
}

TEST(AtomicWrite, ReplacesTheFileAndLeavesNoTemporary) {
  const std::string dir = fresh_dir("atomic");
  const std::string path = dir + "/sub/out.json";  // the folder is created on the way
  write_file_atomic(path, "first");
  write_file_atomic(path, "second");
  EXPECT_EQ(read_text_file(path, "file"), "second");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir + "/sub")) files += e.is_regular_file() ? 1U : 0U;
  EXPECT_EQ(files, 1U);
}

TEST(AtomicWrite, AFullDeviceIsAnError) {
  const std::string m = message_of([] { write_file_atomic("/dev/full", std::string(100, 'x')); });
  EXPECT_NE(m.find("/dev/full: write failed"), std::string::npos) << m;
}

TEST(AtomicWrite, DevicesAreWrittenInPlaceNotReplaced) {
  write_file_atomic("/dev/null", "discarded");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST(AtomicWrite, AFailedWriteKeepsThePreviousFileAndRemovesTheTemporary) {
  const std::string dir = fresh_dir("limit");
  const std::string path = dir + "/out.csv";
  write_file_atomic(path, "old");
  // A file size limit makes the write fail part-way, as a full disk would.
  rlimit old{};
  ::getrlimit(RLIMIT_FSIZE, &old);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 1000;
  ::setrlimit(RLIMIT_FSIZE, &small);
  const std::string m = message_of([&] { write_file_atomic(path, std::string(5000, 'x')); });
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(m.find("write failed"), std::string::npos) << m;
  EXPECT_EQ(read_text_file(path, "file"), "old");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1U);
}

TEST(StrictJson, ADuplicateKeyIsRefusedWithItsPath) {
  EXPECT_EQ(parse_json_strict(R"({"a": 1, "b": [1, {"c": 2}]})")["b"][1]["c"], 2);
  const std::string m = message_of([] { parse_json_strict(R"({"s": [{"n": "x"}, {"n": "y", "d": 1, "d": 2}]})"); });
  EXPECT_NE(m.find("field 's[1].d': duplicate key"), std::string::npos) << m;
  EXPECT_NE(message_of([] { parse_json_strict(R"({"a": 1, "a": 1})"); }).find("field 'a': duplicate key"), std::string::npos);
  // Equal keys in different objects are fine.
  EXPECT_NO_THROW(parse_json_strict(R"([{"a": 1}, {"a": 2}, {"x": {"a": 3}}])"));
}

TEST(StrictJson, InvalidTextAndDeepNestingAreRefused) {
  EXPECT_NE(message_of([] { parse_json_strict("{"); }).find("not valid JSON"), std::string::npos);
  EXPECT_NE(message_of([] { parse_json_strict(std::string(100000, '[')); }).find("nested deeper than"), std::string::npos);
}

TEST(StrictJson, NonFiniteNumbersAndNullAreFoundByPath) {
  nlohmann::json j = {{"cost", {{"total", 1.0}, {"state", std::numeric_limits<double>::infinity()}}}};
  EXPECT_EQ(first_non_finite(j), "cost.state");
  j["cost"]["state"] = 0.5;
  EXPECT_EQ(first_non_finite(j), "");
  j["list"] = {1.0, std::nan("")};
  EXPECT_EQ(first_non_finite(j), "list[1]");
  EXPECT_EQ(first_non_finite_number(j), "list[1]");
  EXPECT_NE(message_of([&] { dump_finite(j); }).find("field 'list[1]' is not a finite number"), std::string::npos);
  // An explicit null is a result's own "not applicable" (an unbounded delta_t): found by the
  // strict check the fuzz oracles use, written by dump_finite.
  j["list"] = {1.0, nullptr};
  EXPECT_EQ(first_non_finite(j), "list[1]");
  EXPECT_EQ(first_non_finite_number(j), "");
  EXPECT_NO_THROW(dump_finite(j));
}

TEST(ChildProcess, ArgumentsReachTheProgramUnchanged) {
  const std::string dir = fresh_dir("argv");
  // Everything a shell would interpret is plain data here.
  const std::string hostile = "x'; touch " + dir + "/pwned; echo '$(touch " + dir + "/pwned2)`touch " + dir + "/p3`";
  ProcessSpec spec;
  spec.argv = {"printf", "%s|", hostile, "a b"};
  const CapturedRun r = run_captured(spec);
  EXPECT_TRUE(r.status.success()) << r.status.describe();
  EXPECT_EQ(r.output, hostile + "|a b|");
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(ChildProcess, RunsInTheGivenFolderAndReportsExitCodes) {
  const std::string dir = fresh_dir("it's a dir");
  ProcessSpec spec;
  spec.argv = {"pwd"};
  spec.working_dir = dir;
  EXPECT_EQ(run_captured(spec).output, fs::canonical(dir).string() + "\n");
  spec.argv = {"false"};
  const CapturedRun r = run_captured(spec);
  EXPECT_TRUE(r.status.exited);
  EXPECT_EQ(r.status.code, 1);
}

TEST(ChildProcess, AMissingProgramIsAClearError) {
  ProcessSpec spec;
  spec.argv = {"oneshot-no-such-program"};
  EXPECT_NE(message_of([&] { ChildProcess c(spec); }).find("oneshot-no-such-program: not found"), std::string::npos);
  spec.argv = {"true"};
  spec.working_dir = "/nonexistent/folder";
  EXPECT_NE(message_of([&] { ChildProcess c(spec); }).find("cannot enter the folder"), std::string::npos);
}

TEST(ChildProcess, RunsInItsOwnProcessGroupAndIsEndedWithIt) {
  ProcessSpec spec;
  spec.argv = {"sleep", "600"};
  ChildProcess child(spec);
  EXPECT_EQ(::getpgid(child.pid()), child.pid());
  EXPECT_NE(::getpgid(child.pid()), ::getpgid(0));
  const ExitStatus s = child.terminate(2000);
  EXPECT_FALSE(s.exited);
  EXPECT_EQ(s.signal, SIGTERM);
  EXPECT_EQ(::kill(child.pid(), 0), -1);  // reaped: gone
}

TEST(ChildProcess, WaitForIsBounded) {
  ProcessSpec spec;
  spec.argv = {"sleep", "600"};
  ChildProcess running(spec);
  EXPECT_FALSE(running.wait_for(20));  // still running: returns after the timeout
  EXPECT_EQ(running.terminate(2000).signal, SIGTERM);
  spec.argv = {"true"};
  ChildProcess quick(spec);
  EXPECT_TRUE(quick.wait_for(60000));  // ends long before the bound
  EXPECT_TRUE(quick.wait().success());
  EXPECT_TRUE(quick.wait_for(0));  // already reaped
}

enum class Shade { kLight, kDark, kUnlisted };
constexpr EnumName<Shade> kShadeNames[] = {{Shade::kLight, "light"}, {Shade::kDark, "dark"}};

TEST(EnumNames, OneTableWritesReadsAndListsTheNames) {
  for (const EnumName<Shade>& e : kShadeNames) {
    EXPECT_STREQ(enum_name(kShadeNames, e.value), e.name);
    EXPECT_EQ(enum_value(kShadeNames, e.name), e.value);
  }
  EXPECT_STREQ(enum_name(kShadeNames, Shade::kUnlisted), "?");
  EXPECT_FALSE(enum_value(kShadeNames, "Light").has_value());  // exact, case-sensitive
  EXPECT_FALSE(enum_value(kShadeNames, "").has_value());
  EXPECT_EQ(enum_names(kShadeNames), (std::vector<std::string>{"light", "dark"}));
  EXPECT_EQ(enum_name_list(kShadeNames), "light, dark");
  static_assert(enum_name(kShadeNames, Shade::kDark)[0] == 'd', "usable in constant expressions");
}

}  // namespace
}  // namespace oneshot::util
