#pragma once
// A progress indicator on stderr for long work. Quiet when stderr is not a
// terminal or when asked (--quiet); then only nothing is printed.

#include <chrono>
#include <string>

namespace sf::cli {

class Progress {
 public:
  // `total` = number of work units (0 = unknown); `label` names the stage.
  Progress(std::string label, long total, bool quiet);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Reports that `done` units are finished; redraws at most ~10 times a second.
  void update(long done);
  // Finishes the line with the elapsed time.
  void finish();

  bool enabled() const { return enabled_; }

  // Whether progress would be shown on this process's stderr.
  static bool stderr_is_terminal();

 private:
  void draw(long done, bool final);

  std::string label_;
  long total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// One status line on stderr ("gsa: fitting undeformed surface ...") unless quiet.
void status(bool quiet, const std::string& message);

}  // namespace sf::cli
