#pragma once
// Atomic outputs (CONTRACT.md: a failed run leaves no half-written output looking complete).
//
//   AtomicOutputDir out("results");          // files go to results.tmp-<pid>-<n>/ first
//   write_something(out.path("strains.csv"));
//   write_something(out.path("steps/step_0001.vtu"));  // subdirectories are fine
//   out.commit();                            // now results/ holds them, all at once
//
// One mechanism for every command that writes a folder (gsa analyse, gsa plot, gsa
// digitise synth, simform run, simform stability):
//   - a lock: the constructor takes an exclusive flock() on ".NAME.lock" beside the
//     folder, held until destruction; a second run into the same folder stops at once
//     with sf::Error "NAME: another run (process P) is writing this folder now ...";
//   - stale temporaries: under the lock, "NAME.tmp-PID-N" and "NAME.old-PID-N" siblings
//     of processes that no longer run (killed) are removed; a folder lost between the two
//     renames of the fallback swap (below) is put back first;
//   - commit() swaps the whole folder in one step: the files of the old folder that this
//     run did not write and that are not `owned` outputs (the user's own files) are
//     hard-linked into the temporary folder, then the two are exchanged with
//     renameat2(RENAME_EXCHANGE) and the old one is removed. A reader (or a kill) sees
//     either the old complete folder or the new complete folder, never a mix. Where the
//     file system cannot exchange, the old folder is renamed aside ("NAME.old-PID-N"),
//     the new one renamed in and the old removed (for an instant there is no folder).
//
// Without commit() (an exception unwinds past it) the destructor removes the temporary
// directory and the final directory is untouched. A process killed outright leaves a
// "NAME.tmp-*" sibling behind; the next run into NAME removes it.
//
// A resumable run (OutputDirOptions::work_suffix, simform run) writes into a fixed
// working folder "NAME<suffix>" that is kept when the run is killed or fails, so a later
// run can continue in it (OutputDirOptions::resume).

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace sf::io {

struct OutputDirOptions {
  // Top-level names in the old folder that are outputs of the command (shell patterns,
  // e.g. "*.png", "steps"): not carried into the new folder even when this run did not
  // write them, so results of two runs never mix. Every other old entry this run did not
  // write is kept.
  std::vector<std::string> owned;
  // Non-empty (e.g. ".partial"): the working folder is NAME<work_suffix>, kept after a
  // failure or a kill (never cleaned as stale).
  std::string work_suffix;
  // With work_suffix: continue in an existing working folder instead of starting empty.
  bool resume = false;
};

class AtomicOutputDir {
 public:
  // Takes the lock, cleans stale temporaries, creates the temporary sibling directory (and
  // any missing parents). The final directory is neither created nor changed before
  // commit(). Throws sf::Error if it cannot create or another run holds the lock.
  explicit AtomicOutputDir(const std::filesystem::path& final_dir, const OutputDirOptions& options = {});
  ~AtomicOutputDir();
  AtomicOutputDir(const AtomicOutputDir&) = delete;
  AtomicOutputDir& operator=(const AtomicOutputDir&) = delete;

  // Where to write the output file `name` (a relative path such as "summary.json" or
  // "steps/a.vtu"; its parent directories are created in the temporary directory).
  // Throws std::logic_error for an absolute name, one with "..", or after commit().
  std::string path(const std::string& name) const;

  // Hard-links (or copies) every entry of the existing final folder into the working
  // folder, so a resumed run starts from the committed results. Entries already there are
  // kept. Returns false when there is no final folder.
  bool seed_from_final();

  // Replaces the final directory by the temporary one in one step (see the header).
  // Throws sf::Error naming the folder on failure; throws std::logic_error if called twice.
  void commit();

  const std::filesystem::path& final_dir() const { return final_dir_; }
  const std::filesystem::path& temp_dir() const { return temp_dir_; }
  bool committed() const { return committed_; }

 private:
  std::filesystem::path final_dir_;
  std::filesystem::path temp_dir_;
  OutputDirOptions options_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

// Removes "NAME.tmp-PID-N" / "NAME.old-PID-N" siblings of `final_dir` whose process is not
// running, and puts back a folder lost between the renames of a fallback swap. Called by
// AtomicOutputDir under its lock; returns the number of entries removed.
int clean_stale_temporaries(const std::filesystem::path& final_dir);

// Writes `content` to `path` through a temporary sibling file ("PATH.tmp-<pid>") and a rename,
// so `path` is either its old self or complete. Throws sf::Error "PATH: cannot write file
// (reason)" on failure (the temporary file is removed).
void write_file_atomic(const std::string& path, const std::string& content);
// Same, with the content produced by `write` into a stream (for large outputs).
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace sf::io
