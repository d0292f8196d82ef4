// libFuzzer target: the STL reader of mesh tools (ASCII and binary; common/io/stl.hpp).
#include "common/io/stl.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  return sf::fuzz::run_reader([&] { (void)sf::io::read_stl_bytes(bytes, "fuzz.stl"); });
}
