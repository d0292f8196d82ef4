#pragma once
// Shared by the libFuzzer targets (tests/fuzz/README.md): the input as a file (the readers
// take paths) and the rule that decides what is a finding.
//
// A reader may reject any input with an sf::Error (sf::InputError naming the file, line,
// column): that is the documented behaviour. Anything else escaping it (std::out_of_range,
// std::logic_error, nlohmann or yaml-cpp exceptions, ...) is what users see as "internal
// error, please report": the target aborts, and libFuzzer records the input as a crash. So
// do the sanitizers for memory errors and undefined behaviour.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "common/core/error.hpp"

namespace sf::fuzz {

// The bytes as a file: one memory file per process, rewritten for each input.
inline std::string as_file(const std::uint8_t* data, std::size_t size) {
  static const int fd = ::memfd_create("sf_fuzz_input", 0);
  if (fd < 0) std::abort();
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) std::abort();
  return "/proc/self/fd/" + std::to_string(fd);
}

template <class F>
int run_reader(F&& f) {
  try {
    f();
  } catch (const sf::Error&) {
    // a clear, documented rejection
  } catch (const std::exception& e) {
    std::fprintf(stderr, "finding: an exception other than sf::Error escaped the reader: %s\n", e.what());
    std::abort();
  }
  return 0;
}

}  // namespace sf::fuzz
