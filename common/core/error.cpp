#include "common/core/error.hpp"

#include <cstdio>
#include <cstdlib>

namespace sf {

std::string located_message(const std::string& file, int line, int column, const std::string& message) {
  std::string out = file;
  if (line > 0) {
    out += ":" + std::to_string(line);
    if (column > 0) out += ":" + std::to_string(column);
  }
  out += ": " + message;
  return out;
}

namespace detail {
void assert_fail(const char* expr, const char* file, int line, const std::string& msg) {
  std::fprintf(stderr, "%s:%d: internal assertion failed: %s (%s)\n", file, line, expr, msg.c_str());
  std::abort();  // Debug builds only: a programming error, never bad input.
}
}  // namespace detail

}  // namespace sf
