#pragma once
// Atomic outputs (CONTRACT.md: a failed run leaves no half-written output looking complete).
//
//   AtomicOutputDir out("results");          // files go to results.tmp-<pid>-<n>/ first
//   write_something(out.path("strains.csv"));
//   write_something(out.path("steps/step_0001.vtu"));  // subdirectories are fine
//   out.commit();                            // now results/ holds them
//
// Without commit() (an exception unwinds past it) the destructor removes the temporary
// directory and the final directory is untouched. A process killed outright can leave a
// "DIR.tmp-*" sibling behind; it never looks like a finished output.

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace sf::io {

class AtomicOutputDir {
 public:
  // Creates the temporary sibling directory (and any missing parents). The final directory
  // is neither created nor changed before commit(). Throws sf::Error if it cannot create.
  explicit AtomicOutputDir(const std::filesystem::path& final_dir);
  ~AtomicOutputDir();
  AtomicOutputDir(const AtomicOutputDir&) = delete;
  AtomicOutputDir& operator=(const AtomicOutputDir&) = delete;

  // Where to write the output file `name` (a relative path such as "summary.json" or
  // "steps/a.vtu"; its parent directories are created in the temporary directory).
  // Throws std::logic_error for an absolute name, one with "..", or after commit().
  std::string path(const std::string& name) const;

  // Moves every file written into the temporary directory to the final directory (created
  // if absent; when absent, the whole directory is moved in one rename). Existing files of
  // the same names are replaced now, each by an atomic rename; other files are kept.
  // Throws sf::Error naming the file on failure; throws std::logic_error if called twice.
  void commit();

  const std::filesystem::path& final_dir() const { return final_dir_; }
  const std::filesystem::path& temp_dir() const { return temp_dir_; }
  bool committed() const { return committed_; }

 private:
  std::filesystem::path final_dir_;
  std::filesystem::path temp_dir_;
  bool committed_ = false;
};

// Writes `content` to `path` through a temporary sibling file ("PATH.tmp-<pid>") and a rename,
// so `path` is either its old self or complete. Throws sf::Error "PATH: cannot write file
// (reason)" on failure (the temporary file is removed).
void write_file_atomic(const std::string& path, const std::string& content);
// Same, with the content produced by `write` into a stream (for large outputs).
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace sf::io
