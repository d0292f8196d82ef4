// libFuzzer target: the CSV reader underneath every table (common/io/csv.hpp), with
// delimiter detection.
#include "common/io/csv.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  return sf::fuzz::run_reader([&] {
    const sf::io::CsvTable t = sf::io::read_csv_string(std::move(text), "fuzz.csv");
    (void)t;
  });
}
