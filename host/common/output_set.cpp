#include "host/common/output_set.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "host/common/input_error.h"

namespace sigmafem {
namespace fs = std::filesystem;

namespace {

constexpr const char* kStagingFolder = ".sigmafem-partial";

void move_into_place(const fs::path& from, const fs::path& to) {
  std::error_code error;
  fs::rename(from, to, error);
  if (error)
    throw std::runtime_error(to.string() + ": cannot move the new file into place: " + error.message() +
                             " (the folder now lacks the set's marker: the run is incomplete)");
}

}  // namespace

OutputSet::OutputSet(std::string out_dir, std::vector<std::string> names, std::string marker)
    : out_dir_(std::move(out_dir)),
      staging_dir_((fs::path(out_dir_) / kStagingFolder).string()),
      marker_(std::move(marker)),
      names_(std::move(names)) {
  std::error_code error;
  fs::create_directories(out_dir_, error);
  if (error) throw InputError(out_dir_ + ": cannot create output folder: " + error.message());
  fs::remove_all(staging_dir_, error);   // a killed run's leftovers
  fs::create_directory(staging_dir_, error);
  if (error) throw InputError(out_dir_ + ": cannot create a folder in the output folder: " + error.message());
}

OutputSet::~OutputSet() {
  std::error_code ignored;
  fs::remove_all(staging_dir_, ignored);
}

std::string OutputSet::staged(const std::string& name) const { return (fs::path(staging_dir_) / name).string(); }

std::string OutputSet::final_path(const std::string& name) const { return (fs::path(out_dir_) / name).string(); }

void OutputSet::publish() {
  const fs::path out(out_dir_), staging(staging_dir_);
  std::error_code error;
  // The old set goes first, its marker before the rest.
  fs::remove(out / marker_, error);
  if (error) throw std::runtime_error(final_path(marker_) + ": cannot remove the previous run's file: " + error.message());
  for (const std::string& name : names_) {
    fs::remove_all(out / name, error);
    if (error) throw std::runtime_error(final_path(name) + ": cannot remove the previous run's file: " + error.message());
  }
  for (const fs::directory_entry& entry : fs::directory_iterator(staging)) {
    const fs::path name = entry.path().filename();
    if (name != marker_) move_into_place(entry.path(), out / name);
  }
  if (fs::exists(staging / marker_)) move_into_place(staging / marker_, out / marker_);
  fs::remove_all(staging, error);
}

}  // namespace sigmafem
