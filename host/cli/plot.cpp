#include "host/cli/plot.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "host/data/csv_format.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;

namespace {

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

std::string quoted(const std::string& path) { return "'" + replace_all(path, "'", "''") + "'"; }

}  // namespace

bool gnuplot_available() {
  return std::system("gnuplot -e \"set terminal pngcairo\" >/dev/null 2>&1") == 0;
}

void render_plot(const PlotData& data, const std::string& script, const std::string& png_path) {
  const fs::path partial = png_path + ".partial.png";
  const fs::path work = fs::path(png_path + ".plot");
  fs::create_directories(work);
  const fs::path data_file = work / "data.txt", script_file = work / "plot.gp";
  {
    std::ofstream out(data_file);
    out << '#';
    for (const std::string& column : data.columns) out << ' ' << column;
    out << '\n';
    for (const auto& row : data.rows) {
      for (std::size_t c = 0; c < row.size(); ++c) out << (c ? " " : "") << format_number(row[c]);
      out << '\n';
    }
  }
  {
    std::ofstream out(script_file);
    out << "set terminal pngcairo size 1200,700 font ',11' noenhanced\n"
        << replace_all(replace_all(script, "$data", quoted(data_file.string())), "$output",
                       quoted(partial.string()));
  }
  const std::string command = "gnuplot " + quoted(script_file.string()) + " 2>" +
                              quoted((work / "log.txt").string());
  const int status = std::system(command.c_str());
  std::string log;
  if (status != 0) {
    std::ifstream in(work / "log.txt");
    std::ostringstream text;
    text << in.rdbuf();
    log = text.str();
  }
  std::error_code ignored;
  fs::remove_all(work, ignored);
  if (status != 0 || !fs::exists(partial)) {
    fs::remove(partial, ignored);
    throw std::runtime_error("gnuplot failed to draw " + png_path + ": " + log);
  }
  fs::rename(partial, png_path);
}

}  // namespace sigmafem::cli
