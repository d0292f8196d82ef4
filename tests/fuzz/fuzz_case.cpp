// libFuzzer target: the YAML case reader and its checks (`simform check`;
// forming/case/reader.hpp). check_case_text returns problems, it must never throw.
#include <cstdio>

#include "forming/case/reader.hpp"
#include "tests/fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Tool files named in the text resolve below a folder that does not exist (no reads of
  // arbitrary files such as /dev/zero).
  return sf::fuzz::run_reader([&] {
    const sf::forming::CaseCheck c = sf::forming::check_case_text(text, "/nonexistent-sf-fuzz/case.yaml");
    for (std::size_t i = 0; i < c.problems.size(); ++i) (void)c.located(i);
  });
}
