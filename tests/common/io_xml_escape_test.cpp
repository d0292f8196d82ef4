// The one XML/HTML escape (common/io/xml_escape.hpp): every special character
// becomes its entity, everything else (UTF-8 included) passes through, and an
// escaped text never holds a bare special character.
#include <gtest/gtest.h>

#include <string>

#include "common/io/xml_escape.hpp"

namespace sf::io {
namespace {

TEST(IoXmlEscape, ReplacesTheFiveSpecialCharacters) {
  EXPECT_EQ(xml_escape("a < b & \"c\" > 'd'"), "a &lt; b &amp; &quot;c&quot; &gt; &apos;d&apos;");
  EXPECT_EQ(xml_escape("&amp;"), "&amp;amp;");  // escaping twice escapes the ampersand again
}

TEST(IoXmlEscape, KeepsOtherTextAsItIs) {
  EXPECT_EQ(xml_escape(""), "");
  EXPECT_EQ(xml_escape("dome/grid.csv"), "dome/grid.csv");
  EXPECT_EQ(xml_escape("\xC2\xB0 \xCE\xB4 mm\xC2\xB2"), "\xC2\xB0 \xCE\xB4 mm\xC2\xB2");  // UTF-8 bytes untouched
}

TEST(IoXmlEscape, ResultHoldsNoBareSpecialCharacter) {
  std::string all;
  for (int c = 1; c < 128; ++c) all += static_cast<char>(c);
  const std::string out = xml_escape(all);
  for (const char c : {'<', '>', '"', '\''}) EXPECT_EQ(out.find(c), std::string::npos) << c;
  // Every '&' starts one of the five entities.
  for (std::size_t at = out.find('&'); at != std::string::npos; at = out.find('&', at + 1)) {
    const std::string rest = out.substr(at, 6);
    EXPECT_TRUE(rest.rfind("&amp;", 0) == 0 || rest.rfind("&lt;", 0) == 0 || rest.rfind("&gt;", 0) == 0 ||
                rest.rfind("&quot;", 0) == 0 || rest.rfind("&apos;", 0) == 0)
        << rest;
  }
}

}  // namespace
}  // namespace sf::io
