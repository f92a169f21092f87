/// @file output_files.hpp
/// @brief CSV, JSON and text files of the experiments, and plots drawn by gnuplot.
///
/// Every file is written atomically (oneshot/util/file_io.hpp) and every write is checked;
/// a number that is not finite is refused with the field named instead of being written as
/// `nan` or `null`. Folders are created when the first file goes into them, so a run
/// refused before it starts leaves nothing behind.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace oneshot::util {

/// What write_csv does with a NaN or infinite value.
enum class NonFinite {
  kRefuse,  ///< std::runtime_error naming the row and column (the default: a run diverged by mistake).
  kMissing  ///< Written as `nan` (gnuplot: `set datafile missing 'nan'`), for studies where a divergence
            ///< is the finding itself (a filter below the critical arrival rate) and is reported beside.
};

/// Writes a CSV: header line, then rows of numbers with 9 significant digits; NaN or infinite
/// values as `non_finite` says.
void write_csv(const std::string& path, const std::vector<std::string>& header,
               const std::vector<std::vector<double>>& rows,
               NonFinite non_finite = NonFinite::kRefuse);

/// Writes `j` pretty-printed to `path`, or to standard output when path is "-"
/// (std::runtime_error naming the field when a number is NaN or infinite; an explicit null passes).
void write_json(const std::string& path, const nlohmann::json& j);

/// Writes `text` to `path`.
void write_text(const std::string& path, const std::string& text);

/// The path of the file `name` in the folder `dir` (dir / name).
std::string path_in(const std::string& dir, const std::string& name);

/// Creates `dir` (and parents); std::runtime_error naming it when impossible.
void make_directory(const std::string& dir);

/// `label` as a gnuplot string constant: single-quoted (no backquote or macro
/// substitution happens inside), quotes doubled, control characters as spaces.
std::string gnuplot_quote(const std::string& label);

/// The line that opens a PNG plot of a gnuplot script: "set terminal pngcairo size W,H font
/// 'Sans,F' noenhanced" (labels printed as written) and a newline.
std::string gnuplot_png_terminal(int width_px, int height_px, int font_pt = 11);

/// Writes `script` to dir/script_name and runs gnuplot on it in `dir` (argument vector, no
/// shell; the folder's name never enters the script); std::runtime_error with gnuplot's
/// message on failure, or when gnuplot is not installed (apt-get install gnuplot-nox).
void run_gnuplot(const std::string& dir, const std::string& script_name, const std::string& script);

}  // namespace oneshot::util
