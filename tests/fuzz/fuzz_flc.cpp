// libFuzzer target: the forming limit curve file of --flc (gsa/flc.hpp).
#include "gsa/flc.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = sf::fuzz::as_file(data, size);
  return sf::fuzz::run_reader([&] { (void)sf::gsa::read_flc(path); });
}
