// Bad input as a hostile or careless user gives it, one test per class of fault (issue 14):
// names that would become paths, numbers that would overflow, readers that would never end,
// limits checked before allocation, messages that name what is wrong, nothing accepted in
// silence. Each asserts the exit code, that the message names the file and the field or line,
// and that nothing is written under an output's final name.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/sigmafem_command.h"
#include "temp_path.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test::CommandRun;
using test::run_sigmafem;
using test::run_sigmafem_command;

// A reader that blocks would hang the test instead of failing it: every command here runs
// under a timeout, and a run it kills fails the exit-code check (124).
CommandRun run_with_timeout(const std::string& arguments) {
  return run_sigmafem_command("timeout 60 " + std::string(SIGMAFEM_BINARY) + " " + arguments);
}

class BadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path scenarios = fs::path(SIGMAFEM_SOURCE_DIR) / "scenarios";
    fs::copy_file(scenarios / "box.msh", dir_.file("box.msh"));
    std::ifstream in(scenarios / "box.json");
    box_ = json::parse(in);
    box_["time"]["steps"] = 5;
  }

  std::string scenario_file(const json& scenario, const std::string& name = "variant.json") const {
    return dir_.write(name, scenario.dump(2));
  }
  std::string out() const { return dir_.file("out"); }

  // Exit 2, the message naming every one of `named`, and no output folder.
  void expect_refused(const CommandRun& run, const std::vector<std::string>& named, const std::string& case_name) {
    EXPECT_EQ(run.exit_code, 2) << case_name << ": " << run.output;
    for (const std::string& name : named)
      EXPECT_NE(run.output.find(name), std::string::npos) << case_name << ": the message names " << name << ": "
                                                          << run.output;
    EXPECT_FALSE(fs::exists(out())) << case_name << ": nothing written after bad input";
  }

  // generate on box.json (5 steps) changed by `edit`: refused, naming the file and `field`.
  void expect_scenario_refused(const std::function<void(json&)>& edit, const std::string& field) {
    json scenario = box_;
    edit(scenario);
    const CommandRun run = run_with_timeout("generate " + scenario_file(scenario) + " --out " + out() + " --quiet");
    expect_refused(run, {"variant.json", field}, field);
  }

  // Data for `estimate`: box.json, 5 steps, into dir_/data.
  std::string generate_data() const {
    const std::string data = dir_.file("data");
    const CommandRun run = run_sigmafem("generate " + scenario_file(box_, "box5.json") + " --out " + data +
                                        " --vtk-every 0 --quiet");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return data;
  }
  CommandRun estimate(const std::string& data, const std::string& extra = "") const {
    return run_with_timeout("estimate " + dir_.file("box5.json") + " --data " + data + " --out " + out() +
                            " --quiet " + extra);
  }

  test::TempDir dir_{"sigmafem_bad_input"};
  json box_;
};

// A scenario's name becomes NAME.pvd and vtk/NAME_000000.vtu: "../" wrote outside --out, a
// newline broke the CSV header, a long name failed after the data files were in place.
TEST_F(BadInputTest, ANameThatCannotBeAFileNameIsRefusedBeforeAnythingIsWritten) {
  for (const std::string& name : {std::string("../escaped"), std::string("a/b"), std::string("two\nlines"),
                                  std::string(300, 'x'), std::string(".hidden"), std::string("it's")}) {
    json scenario = box_;
    scenario["name"] = name;
    scenario["output"]["vtk_every"] = 1;
    const CommandRun run = run_with_timeout("generate " + scenario_file(scenario) + " --out " + out() + " --quiet");
    expect_refused(run, {"variant.json", "name:"}, "name " + name.substr(0, 20));
    EXPECT_FALSE(fs::exists(dir_.file("escaped.pvd"))) << "nothing outside --out";
  }
  // Without a name field the file name is the name: the message says to give one.
  json unnamed = box_;
  unnamed.erase("name");
  const CommandRun run =
      run_with_timeout("generate " + scenario_file(unnamed, "my+liver.json") + " --out " + out() + " --quiet");
  expect_refused(run, {"my+liver.json", "name (from the file name)", "give a \"name\" field"}, "file name");
}

// Finite numbers whose products overflow: CG's stop test tol * |b| became inf and passed at
// once, so the organ never moved and the run exited 0.
TEST_F(BadInputTest, NumbersBeyondThePhysicalRangeAreRefusedWhereTheyAreRead) {
  expect_scenario_refused([](json& s) { s["gravity"] = {0.0, 0.0, 1e300}; }, "gravity[2]");
  expect_scenario_refused([](json& s) { s["control"]["stiffness"] = 1e300; }, "control.stiffness");
  expect_scenario_refused([](json& s) { s["material"]["young_modulus"] = 1e300; }, "material.young_modulus");
  expect_scenario_refused([](json& s) { s["observations"]["noise_std"] = 1e300; }, "observations.noise_std");
  expect_scenario_refused([](json& s) { s["filter"]["observation_std"] = 1e300; }, "filter.observation_std");
  // A literal beyond double range: the JSON library's exception (exit 1) before; now the line.
  json scenario = box_;
  scenario["gravity"] = {0.0, 0.0, 12345.0};
  std::string text = scenario.dump(2);
  text.replace(text.find("12345.0"), 7, "1e400");
  const CommandRun literal = run_with_timeout("generate " + dir_.write("variant.json", text) + " --out " + out());
  expect_refused(literal, {"variant.json", "line ", "1e400"}, "1e400");
  // A trajectory file with a coordinate near the largest double.
  dir_.write("path.csv", "time,x,y,z\n0,0,0,0\n1,1e308,0,0\n");
  expect_scenario_refused(
      [&](json& s) { s["control"]["trajectory"] = {{"type", "file"}, {"file", "path.csv"}}; }, "path.csv line 3");
  // The same ranges on the command line, NaN included (CLI11's checks passed it).
  for (const std::string option : {"--noise-std 1e308", "--noise-std nan", "--inject gravity=0,0,1e300"}) {
    const CommandRun run = run_with_timeout("generate " + scenario_file(box_) + " --out " + out() + " " + option);
    expect_refused(run, {option.substr(0, option.find(' '))}, option);
  }
}

TEST_F(BadInputTest, DataRowsWithAbsurdOrNoValuesAreRefusedNamingTheLine) {
  const std::string data = generate_data();
  const std::string csv = data + "/observations.csv";
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  in.close();
  // Rewrites the file with the row of step 2 changed.
  auto write_with = [&](const std::function<std::string(const std::string&)>& change_row) {
    std::ofstream rewritten(csv);
    for (const std::string& line : lines) rewritten << (line.rfind("2,", 0) == 0 ? change_row(line) : line) << '\n';
  };
  // An SO coordinate of 1e300 m: skipped, and the verdict "consistent", before.
  write_with([](const std::string& line) {
    const size_t so_x = line.find(',', line.find(',') + 1) + 1;
    return line.substr(0, so_x) + "1e300" + line.substr(line.find(',', so_x));
  });
  CommandRun run = estimate(data);
  expect_refused(run, {"observations.csv line", "so_x", "metres"}, "SO coordinate 1e300");
  EXPECT_EQ(run.output.find("consistent"), std::string::npos) << "no verdict on refused data";
  // Every point field empty: gnuplot's own error and a partial output set before.
  std::ofstream blank(csv);
  for (const std::string& line : lines) {
    if (line.empty() || line[0] == '#' || line.rfind("step", 0) == 0) {
      blank << line << '\n';
      continue;
    }
    size_t cut = 0;
    for (int comma = 0; comma < 5; ++comma) cut = line.find(',', cut) + 1;
    std::string row = line.substr(0, cut - 1);
    for (size_t k = 0; k < box_["observations"]["nodes"].size() * 3; ++k) row += ",";
    blank << row << '\n';
  }
  blank.close();
  run = estimate(data);
  expect_refused(run, {"observations.csv", "no observed point has a value"}, "all points empty");
}

// /dev/zero, /dev/urandom, a FIFO or a link to one of them read forever and grew memory.
TEST_F(BadInputTest, ReadersRefuseWhatIsNotARegularFile) {
  const std::string fifo = dir_.file("fifo.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink("/dev/urandom", dir_.file("random.json"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/dev/zero", "character device"}, {fifo, "named pipe"}, {dir_.file("random.json"), "character device"}};
  for (const auto& [path, kind] : cases) {
    const CommandRun run = run_with_timeout("generate " + path + " --out " + out());
    expect_refused(run, {path, kind}, path);
  }
  // The observations: a folder named observations.csv was "empty"; a FIFO blocked.
  const std::string data = generate_data();
  fs::remove(data + "/observations.csv");
  fs::create_directory(data + "/observations.csv");
  expect_refused(estimate(data), {"observations.csv", "is a folder"}, "folder");
  fs::remove(data + "/observations.csv");
  ASSERT_EQ(::mkfifo((data + "/observations.csv").c_str(), 0600), 0);
  expect_refused(estimate(data), {"observations.csv", "named pipe"}, "fifo");
  // A trajectory file that is a device.
  expect_scenario_refused(
      [](json& s) { s["control"]["trajectory"] = {{"type", "file"}, {"file", "/dev/zero"}}; }, "/dev/zero");
}

// time.steps of 1e9 passed the checks and failed with std::bad_alloc (exit 1).
TEST_F(BadInputTest, StepCountsAreLimitedBeforeAnyAllocation) {
  expect_scenario_refused([](json& s) { s["time"]["steps"] = 1000000000; }, "time.steps");
}

TEST_F(BadInputTest, MessagesNameTheWrongColumnAndTheByteOrderMarkIsAccepted) {
  const std::string data = generate_data();
  const std::string csv = data + "/observations.csv";
  std::ifstream in(csv);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  const std::string original = text.str();
  // One header column misspelt: "expected 41 columns, found 41" before.
  std::string misspelt = original;
  misspelt.replace(misspelt.find("p1_y"), 4, "p1_Y");
  std::ofstream(csv) << misspelt;
  expect_refused(estimate(data), {"observations.csv line", "\"p1_Y\", expected \"p1_y\""}, "header");
  // A UTF-8 byte order mark, as a Windows editor writes: accepted like the JSON reader does.
  std::ofstream(csv, std::ios::binary) << "\xEF\xBB\xBF" << original;
  const CommandRun run = estimate(data);
  EXPECT_EQ(run.exit_code, 0) << run.output;
}

// Accepted without a word before: a wrapped seed, NaN options, a truth.csv that does not fit,
// an observed node outside the body.
TEST_F(BadInputTest, NothingIsAcceptedInSilence) {
  for (const std::string option : {"--seed -1", "--seed 1e3"}) {
    const CommandRun run = run_with_timeout("generate " + scenario_file(box_) + " --out " + out() + " " + option);
    expect_refused(run, {"--seed"}, option);
  }
  const std::string data = generate_data();
  expect_refused(estimate(data, "--observation-std nan"), {"--observation-std"}, "--observation-std nan");
  // truth.csv is optional: one that does not fit is a warning naming it, and the run goes on.
  const std::string truth = data + "/truth.csv";
  std::ifstream in(truth);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  std::string renamed = text.str();
  renamed.replace(renamed.find("corner_a"), 8, "corner_z");
  std::ofstream(truth) << renamed;
  CommandRun run = estimate(data);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("warning: truth " + truth), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("not the scenario's"), std::string::npos) << run.output;
  fs::remove_all(out());
  std::ofstream(truth) << text.str().substr(0, text.str().rfind('\n', text.str().size() - 2) + 1);
  run = estimate(data);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("rows, the observations have"), std::string::npos) << run.output;
  fs::remove_all(out());
  // A node no tetrahedron uses (kept so that file indices stay valid) never moves.
  dir_.write("orphan.vtk",
             "# vtk DataFile Version 2.0\norphan\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n"
             "0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n0.5 0.5 0.5\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n");
  json scenario = box_;
  scenario["mesh"]["file"] = "orphan.vtk";
  scenario["ligaments"] = {{{"name", "base"}, {"nodes", {0}}, {"stiffness", 100.0}}};
  scenario["control"]["nodes"] = {3};
  scenario["control"].erase("select");
  scenario["observations"]["nodes"] = {1, 4};
  scenario.erase("filter");
  scenario.erase("events");
  scenario.erase("candidate_regions");
  const CommandRun orphan =
      run_with_timeout("generate " + scenario_file(scenario) + " --out " + out() + " --quiet");
  expect_refused(orphan, {"variant.json", "observations.nodes[1]", "belongs to no tetrahedron"}, "orphan node");
}

// A full disk exited 2, as if the input were bad. A file-size limit stands for it (ulimit -f,
// with SIGXFSZ ignored so that the write fails with EFBIG instead of killing the program).
TEST_F(BadInputTest, AFullDiskIsTheMachinesFailureNotTheInputs) {
  const CommandRun run = run_sigmafem_command("sh -c \"trap '' XFSZ; ulimit -f 1; " + std::string(SIGMAFEM_BINARY) +
                                              " generate '" + scenario_file(box_) + "' --out '" + out() +
                                              "' --vtk-every 0 --quiet\"");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("write failed (disk full?)"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(out() + "/observations.csv")) << "nothing under the final name";
  EXPECT_FALSE(fs::exists(out() + "/.sigmafem-partial")) << "the staging folder is removed";
}

// A run stopped by SIGTERM (or Ctrl-C) leaves nothing: hundreds of vtk.partial/ frames before.
// The signal comes twice at once, as `timeout` sends it (to the program, then to its process
// group): that is one request to stop cleanly, not the second Ctrl-C that ends a run at once.
// The signal is sent once the run writes (its staging folder exists, up to 60 s): a fixed
// 2 s once came before the program had started under a loaded ctest -j 2 (stop 47), and the
// default action then left the folder behind.
TEST_F(BadInputTest, AnInterruptedRunLeavesNoFilesBehind) {
  json scenario = box_;
  scenario["time"]["steps"] = 100000;
  scenario["output"]["vtk_every"] = 1;
  const CommandRun run = run_sigmafem_command(
      "sh -c '" + std::string(SIGMAFEM_BINARY) + " generate " + scenario_file(scenario) + " --out " + out() +
      " --quiet & pid=$!; i=0; while [ ! -d " + out() + "/.sigmafem-partial ] && [ $i -lt 600 ]; do sleep 0.1; "
      "i=$((i+1)); done; sleep 0.5; kill -TERM $pid; kill -TERM $pid; wait $pid'");
  EXPECT_EQ(run.exit_code, 128 + 15) << run.output;
  EXPECT_NE(run.output.find("interrupted by signal 15"), std::string::npos) << run.output;
  ASSERT_TRUE(fs::exists(out())) << "the folder was made before the run";
  EXPECT_TRUE(fs::is_empty(out())) << "no frames, no staging folder, no data files";
}

// Publishing replaces the whole set: a killed run's staging folder and the previous run's
// files of the set go, files that are not the set's stay.
TEST_F(BadInputTest, ARunReplacesThePreviousSetAndAKilledRunsLeftovers) {
  const std::string data = generate_data();
  dir_.write("data/.sigmafem-partial/observations.csv", "left by a run killed with SIGKILL");
  dir_.write("data/notes.txt", "the user's own file");
  dir_.write("data/box.pvd", "a series from a run with VTK frames");
  const CommandRun run = run_sigmafem("generate " + dir_.file("box5.json") + " --out " + data + " --vtk-every 0 --quiet");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_FALSE(fs::exists(data + "/.sigmafem-partial"));
  EXPECT_FALSE(fs::exists(data + "/box.pvd")) << "a series of the old set does not stay beside the new data";
  EXPECT_TRUE(fs::exists(data + "/notes.txt"));
  EXPECT_TRUE(fs::exists(data + "/observations.csv"));
}

}  // namespace
}  // namespace sigmafem
