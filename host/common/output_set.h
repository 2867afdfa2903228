// OutputSet: the files one command writes into its output folder, published as one set.
//
// They are written into a staging folder inside the output folder (<out>/.sigmafem-partial/,
// on the same file system, so that moving a file in is a rename) and published when the
// command completes. Publishing first removes the old set's files, its marker first (the file
// a reader opens first: observations.csv, summary.json, report.json), then moves the new files
// in with the marker last. So a folder holds one run's set, or, after a failure part-way through
// publishing, a set without its marker; never the marker of one run beside another run's files.
// A run that fails or is interrupted (SIGINT, SIGTERM, SIGHUP: host/common/interruption.h)
// removes its staging folder as it unwinds; one killed outright (SIGKILL) leaves it, and the
// next run into the folder removes it. Two runs into the same folder at once are not supported.
#pragma once

#include <string>
#include <vector>

namespace sigmafem {

class OutputSet {
 public:
  // Creates `out_dir` (InputError if it cannot) and a fresh staging folder in it. `names`: every
  // file or folder the command may write, `marker` among them.
  OutputSet(std::string out_dir, std::vector<std::string> names, std::string marker);
  // Removes the staging folder (empty once published).
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Where to write `name` now (in the staging folder).
  std::string staged(const std::string& name) const;
  // The staging folder itself.
  const std::string& staging_folder() const { return staging_dir_; }
  // Where `name` will be once published (for paths recorded in reports).
  std::string final_path(const std::string& name) const;
  // Moves the staged files into place as above; std::runtime_error if a move fails.
  void publish();

 private:
  std::string out_dir_, staging_dir_, marker_;
  std::vector<std::string> names_;
};

}  // namespace sigmafem
