// Plots through gnuplot (Debian's gnuplot-nox): PNG files people look at, drawn by a
// well-kept tool rather than by hand. Each plot writes its data and script to a temporary
// folder, runs gnuplot, and renames the PNG into place when it is complete.
#pragma once

#include <string>
#include <vector>

namespace sigmafem::cli {

// True if a gnuplot that can write PNG files is on the PATH.
bool gnuplot_available();

// A data table for a plot: a header (column names) and rows of numbers.
struct PlotData {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
};

// Runs `script` (gnuplot commands that read '$data' and write to '$output') on `data` and
// writes `png_path` atomically. Throws std::runtime_error with gnuplot's message on failure.
void render_plot(const PlotData& data, const std::string& script, const std::string& png_path);

}  // namespace sigmafem::cli
