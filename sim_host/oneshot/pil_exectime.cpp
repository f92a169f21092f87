/// @file pil_exectime.cpp
/// @brief MCU instruction counts of the control job (QEMU's instruction window), the job-only
///        images' memory and the soft-float calls per job (see run_exectime_target).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>

#include "c_job_host.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/statistics.hpp"
#include "oneshot_experiments.hpp"
#include "pil_job_frames.hpp"

namespace oneshot::sim {

std::pair<std::size_t, std::size_t> image_memory(const std::string& path) {
  const std::string d = util::read_text_file(path, "firmware image", kMaxImageBytes);
  const auto u16 = [&](std::size_t o) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(d.at(o)) | static_cast<unsigned char>(d.at(o + 1)) << 8);
  };
  const auto u32 = [&](std::size_t o) { return u16(o) | u16(o + 2) << 16; };
  std::size_t flash = 0;
  std::size_t ram = 0;
  const std::uint32_t shoff = u32(32);
  const std::uint32_t entsize = u16(46);
  const std::uint32_t num = u16(48);
  for (std::uint32_t i = 0; i < num; ++i) {
    const std::size_t sh = shoff + i * entsize;
    const std::uint32_t type = u32(sh + 4);
    const std::uint32_t flags = u32(sh + 8);
    const std::uint32_t size = u32(sh + 20);
    if ((flags & 0x2U) == 0) continue;  // SHF_ALLOC
    const bool write = (flags & 0x1U) != 0;
    const bool nobits = type == 8;
    if (!write) flash += size;
    if (write && !nobits) {
      flash += size;
      ram += size;
    }
    if (write && nobits) ram += size;
  }
  return {flash, ram};
}

namespace {

/// Approach ids of the generated C99 jobs in the firmware (main.cpp).
constexpr std::uint32_t kCJobApproach = app::pil::kCJobApproach;
constexpr std::uint32_t kCJobOwnArithApproach = app::pil::kCJobOwnArithApproach;

/// Flash, RAM and stack bound of the job-only image of the C job variant (no PIL link).
nlohmann::json c_job_only_image(const PilOptions& base, const std::string& variant) {
  PilOptions p = base;
  const std::string dir = std::filesystem::path(firmware_image_path(p)).parent_path().string();
  const std::string image = dir + "/oneshot-" + base.target + "-cjob-" + variant + ".elf";
  if (!std::filesystem::exists(image)) return nlohmann::json{{"image", image}, {"available", false}};
  const auto [flash, ram] = image_memory(image);
  nlohmann::json j{{"image", image}, {"flash_bytes", flash}, {"ram_static_bytes", ram}};
  std::string stack_text;  // the build's stack bound, when it computed one
  if (std::filesystem::is_regular_file(image + ".stack.txt"))
    stack_text = util::read_text_file(image + ".stack.txt", "stack bound", 4096);
  std::istringstream stack(stack_text);
  std::size_t bound = 0;
  if (stack >> bound) {
    j["stack_bound_bytes"] = bound;
    j["ram_total_bound_bytes"] = ram + bound;
  }
  const bool q15 = variant.rfind("q15_", 0) == 0;  // issue 25: the 16-bit job's tighter budget
  j["flash_target_bytes"] = q15 ? 6 * 1024 : 12 * 1024;
  j["ram_target_bytes"] = q15 ? 512 : 1024;
  return j;
}

/// Calls of the soft-float routines per job of approach `approach` (entries of libgcc's
/// __aeabi_f* / __aeabi_*2f routines and of the generated C job's own integer multiply
/// os_fmul executed inside the job windows), from the instruction profile of a run of its own
/// on the same jobs. os_fmul hands zeros, subnormals and out-of-range results to
/// __aeabi_fmul, so those rare multiplications count twice.
nlohmann::json soft_float_calls(const PilOptions& image, std::uint32_t approach, bool exact_noise, std::uint16_t pwm0,
                                const std::vector<JobRecord>& jobs) {
  namespace fs = std::filesystem;
  PilOptions p = image;
  p.count_instructions = true;
  std::random_device entropy;
  const fs::path dir = fs::temp_directory_path() / ("oneshot-softfloat-" + std::to_string(entropy()) + std::to_string(entropy()));
  p.profile_dir = dir.string();
  std::string elf;
  {
    PilLink link(p);
    elf = link.image();
    app::pil::Frame cfg;
    app::pil::Writer cw(cfg);
    cw.u(approach, 1);
    cw.u(exact_noise ? 1U : 0U, 1);
    cw.u(pwm0, 2);
    link.request(app::pil::Type::kConfig, cfg);
    for (const JobRecord& r : jobs) {
      link.request(app::pil::Type::kSample, sample_frame(r));
    }
  }  // QEMU ends: the plugin writes the profile
  std::map<std::uint32_t, std::string> entries;
  for (const char* name : {"__aeabi_fadd", "__aeabi_fsub", "__aeabi_frsub", "__aeabi_fmul", "__aeabi_fdiv",
                           "__aeabi_fcmpeq", "__aeabi_fcmplt", "__aeabi_fcmple", "__aeabi_fcmpgt", "__aeabi_fcmpge",
                           "__aeabi_i2f", "__aeabi_ui2f", "__aeabi_f2iz", "__aeabi_f2uiz", "os_fmul"}) {
    try {
      entries.emplace(elf_symbol_address(elf, name) & ~1U, name);
    } catch (const PilError&) {
      // not linked into this image
    }
  }
  const fs::path file = dir / (fs::path(elf).stem().string() + ".profile");
  std::istringstream in(fs::exists(file) ? util::read_text_file(file.string(), "instruction profile", kMaxImageBytes) : "");
  fs::remove_all(dir);
  std::map<std::string, double> per_routine;
  double total = 0;
  std::string address;
  std::uint64_t count = 0;
  while (in >> address >> count) {
    const auto it = entries.find(static_cast<std::uint32_t>(std::stoul(address, nullptr, 16)) & ~1U);
    if (it == entries.end()) continue;
    per_routine[it->second] += static_cast<double>(count) / static_cast<double>(jobs.size());
    total += static_cast<double>(count) / static_cast<double>(jobs.size());
  }
  nlohmann::json j{{"per_job", total}};
  for (const auto& [name, n] : per_routine) j["by_routine"][name] = n;
  return j;
}

}  // namespace

nlohmann::json run_exectime_target(const SimContext& ctx, const CommonOptions& opt, const PilOptions& base) {
  if (!ctx.generated()) throw std::invalid_argument("MCU instruction counts use the compiled-in plant: run without --plant");
  // The jobs of 4 s of the reference jitter scenario, recorded on the host (as in exectime).
  Scenario sc;
  sc.name = "exectime";
  sc.duration_s = 4.0;
  sc.amplitude_volts = 0.2;
  sc.change_period_s = 1.0;
  sc.jitter.kind = JitterModel::Kind::kUniform;
  sc.jitter.release_max_us = 20'000;
  sc.jitter.exec_min_us = 200;
  sc.jitter.exec_max_us = 600;
  RunOptions rec = run_options(opt, Approach::kB);
  rec.record_jobs = true;
  rec.format = NumberFormat::kDouble;
  const std::vector<JobRecord> jobs = simulate(ctx, sc, opt.seed, rec).job_records;
  nlohmann::json j;
  j["experiment"] = "exectime";
  j["target"] = base.target;
  j["jobs_per_4s"] = jobs.size();
  j["noise_model"] = opt.noise == NoiseModel::kExact ? "exact" : "constant";
  j["counter"] = "QEMU TCG plugin insn_window: guest instructions between the job markers, marker overhead subtracted";
  for (const char* format : {"float", "fixed"}) {
    for (const char* disc : {"table", "nearest", "generic"}) {
      PilOptions p = base;
      p.format = format;
      p.discretizer = disc;
      p.count_instructions = true;
      PilLink link(p);
      // Marker overhead: begin/end back to back.
      link.request(app::pil::Type::kCalibrate, app::pil::Frame{});
      // B, C, and on table images the generated C99 job (approach id 5, B's job).
      const bool c_job = std::string(disc) != "generic";
      std::vector<std::uint32_t> approaches = {static_cast<std::uint32_t>(Approach::kB),
                                               static_cast<std::uint32_t>(Approach::kC)};
      if (c_job) approaches.push_back(kCJobApproach);
      // Fixed-point table images also carry the q15 C job (approach 6), whose oracle is the
      // same C compiled into this program.
      const bool q15 = c_job && std::string(format) == "fixed" && HostCJob::available(HostCJob::Variant::kQ15Table);
      // Float table images: approach 6 is float_poly, likewise its own oracle.
      const bool poly = c_job && std::string(format) == "float" && std::string(disc) == "table" &&
                        HostCJob::available(HostCJob::Variant::kFloatPoly);
      if (q15 || poly) approaches.push_back(kCJobOwnArithApproach);
      std::vector<std::vector<std::uint8_t>> replies_b;
      std::size_t c_job_identical = 0;
      std::size_t q15_identical = 0;
      for (std::uint32_t a : approaches) {
        app::pil::Frame cfg;
        app::pil::Writer cw(cfg);
        cw.u(a, 1);
        cw.u(opt.noise == NoiseModel::kExact ? 1U : 0U, 1);
        // Initial PWM code: the one nearest 0 V, as in simulate().
        cw.u(static_cast<std::uint32_t>(std::lround(-ctx.design().u_min[0] * ctx.design().steps_per_volt[0])), 2);
        link.request(app::pil::Type::kConfig, cfg);
        std::unique_ptr<HostCJob> host_job;
        if (a == kCJobOwnArithApproach) {
          const HostCJob::Variant variant = poly ? HostCJob::Variant::kFloatPoly
                                            : std::string(disc) == "nearest" ? HostCJob::Variant::kQ15Nearest
                                                                             : HostCJob::Variant::kQ15Table;
          host_job = std::make_unique<HostCJob>(
              variant, static_cast<std::uint16_t>(std::lround(-ctx.design().u_min[0] * ctx.design().steps_per_volt[0])));
        }
        for (const JobRecord& r : jobs) {
          const app::pil::Frame reply = link.request(app::pil::Type::kSample, sample_frame(r));
          const std::vector<std::uint8_t> bytes(reply.payload, reply.payload + reply.length);
          if (a == static_cast<std::uint32_t>(Approach::kB)) replies_b.push_back(bytes);
          // Same inputs, same job: status, τ, saturation, estimate, gain and applied input byte for byte.
          if (a == kCJobApproach && bytes == replies_b.at(static_cast<std::size_t>(&r - jobs.data()))) ++c_job_identical;
          if (host_job) {
            // The MCU's τ (from its timer) and the same codes through the host-compiled C.
            app::pil::Reader head(reply);
            head.u(1);
            const std::int32_t tau = head.s(4);
            const auto y = static_cast<std::uint16_t>(r.y_code);
            const auto sp = static_cast<std::uint16_t>(r.setpoint_code);
            const std::vector<std::int32_t> host = host_job->run(tau, y, sp);
            if (host == reply_values(reply, ctx.plant().n())) ++q15_identical;
          }
        }
      }
      const std::vector<std::uint64_t> counts = link.instruction_counts();
      if (counts.size() != 1 + approaches.size() * jobs.size()) {
        throw PilError("instruction counter: expected " + std::to_string(1 + approaches.size() * jobs.size()) +
                       " windows, got " + std::to_string(counts.size()));
      }
      const auto [flash, ram] = image_memory(link.image());
      const int stack = link.stack_peak_bytes();
      const std::uint64_t overhead = counts[0];
      for (std::size_t v = 0; v < approaches.size(); ++v) {
        std::vector<double> per_job;
        for (std::size_t k = 0; k < jobs.size(); ++k) per_job.push_back(static_cast<double>(counts[1 + v * jobs.size() + k] - overhead));
        const util::Summary s = util::summarize(per_job);
        double total = 0;
        for (double x : per_job) total += x;
        const bool is_q15 = approaches[v] == kCJobOwnArithApproach;
        const std::string name = std::string(v == 0 ? "half" : v == 1 ? "complete" : "c99_half") + "_" + disc + "_" +
                                 (is_q15 ? (poly ? "float_poly" : "q15") : format);
        j["variants"][name] = {{"instructions_per_job", s.mean},
                               {"instructions_per_job_min", *std::min_element(per_job.begin(), per_job.end())},
                               {"instructions_per_job_max", *std::max_element(per_job.begin(), per_job.end())},
                               {"instructions_per_4s", total},
                               {"flash_bytes", flash},
                               {"ram_bytes", ram},
                               {"stack_peak_bytes", stack},
                               {"image", link.image()}};
        if (is_q15 && poly) {
          PilOptions img = base;
          img.format = format;
          img.discretizer = disc;
          j["variants"][name]["noise_model"] = "exact";
          j["variants"][name]["bit_identical_to_host_c_job"] = q15_identical;
          j["variants"][name]["bit_identical_to"] = "the generated float_poly C itself (host gcc), not the C++ core";
          j["variants"][name]["jobs"] = jobs.size();
          j["variants"][name]["job_only_image"] = c_job_only_image(base, "float_poly");
          j["variants"][name]["soft_float_calls"] = soft_float_calls(
              img, kCJobOwnArithApproach, opt.noise == NoiseModel::kExact,
              static_cast<std::uint16_t>(std::lround(-ctx.design().u_min[0] * ctx.design().steps_per_volt[0])), jobs);
          j["variants"][name]["instructions_target"] = 6000;  // Cortex-M0
        } else if (is_q15) {
          j["variants"][name]["noise_model"] = "exact";
          j["variants"][name]["bit_identical_to_host_c_job"] = q15_identical;
          j["variants"][name]["jobs"] = jobs.size();
          j["variants"][name]["job_only_image"] = c_job_only_image(base, std::string("q15_") + disc);
          j["variants"][name]["instructions_target"] = 1000;
        } else if (v == 2) {
          if (std::string(format) == "float") {
            PilOptions img = base;
            img.format = format;
            img.discretizer = disc;
            j["variants"][name]["soft_float_calls"] = soft_float_calls(
                img, kCJobApproach, opt.noise == NoiseModel::kExact,
                static_cast<std::uint16_t>(std::lround(-ctx.design().u_min[0] * ctx.design().steps_per_volt[0])), jobs);
            j["variants"][name]["instructions_target"] = 6000;  // issue 25, Cortex-M0
          }
          // The C job always predicts with the exact Q_d(τ): compared with B only under that model.
          j["variants"][name]["noise_model"] = "exact";
          j["variants"][name]["bit_identical_to"] = "the C++ job of this image (approach B), byte for byte";
          if (opt.noise == NoiseModel::kExact) {
            j["variants"][name]["bit_identical_to_cpp_jobs"] = c_job_identical;
          } else {
            j["variants"][name]["note"] = "B ran with the constant Q: use --noise-model exact to compare";
          }
          j["variants"][name]["jobs"] = jobs.size();
          j["variants"][name]["job_only_image"] = c_job_only_image(base, std::string(format) + "_" + disc);
        }
      }
      j["marker_overhead_instructions"] = overhead;
    }
  }
  return j;
}

}  // namespace oneshot::sim
