#include "common/cli/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace sf::cli {

bool Progress::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

Progress::Progress(std::string label, long total, bool quiet)
    : label_(std::move(label)),
      total_(total),
      enabled_(!quiet && stderr_is_terminal()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  if (!finished_) finish();
}

void Progress::update(long done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(done, false);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (enabled_) draw(total_, true);
}

void Progress::draw(long done, bool final) {
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (total_ > 0) {
    const double pct = 100.0 * static_cast<double>(done) / static_cast<double>(total_);
    std::fprintf(stderr, "\r%s: %5.1f%% (%ld/%ld) %.1f s%s", label_.c_str(), pct, done, total_, secs,
                 final ? "\n" : "");
  } else {
    std::fprintf(stderr, "\r%s: %ld %.1f s%s", label_.c_str(), done, secs, final ? "\n" : "");
  }
  std::fflush(stderr);
}

void status(bool quiet, const std::string& message) {
  if (quiet) return;
  std::fprintf(stderr, "%s\n", message.c_str());
}

}  // namespace sf::cli
