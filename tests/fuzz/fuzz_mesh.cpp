// libFuzzer target: the user mesh file of gsa analyse --mesh (gsa/mesh_file.hpp).
#include "gsa/mesh_file.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = sf::fuzz::as_file(data, size);
  return sf::fuzz::run_reader([&] { (void)sf::gsa::read_mesh_file(path); });
}
