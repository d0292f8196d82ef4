// libFuzzer target: the grid file reader (CSV, measuring-system exports, detection of
// format, delimiter and decimal separator; common/io/grid_file.hpp).
#include "common/io/grid_file.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = sf::fuzz::as_file(data, size);
  return sf::fuzz::run_reader([&] {
    const sf::io::GridData g = sf::io::read_grid_file(path);
    (void)g;
  });
}
