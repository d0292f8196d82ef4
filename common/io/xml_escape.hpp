#pragma once
// Escaping text for XML and HTML: the one place that knows the five entities.
//
//   xml_escape("a < b & \"c\"")  ->  "a &lt; b &amp; &quot;c&quot;"
//
// The result is safe in element content and in attribute values quoted with either
// " or '. Used by the VTK collection files (.pvd) and gsa's report.html.

#include <string>
#include <string_view>

namespace sf::io {

// Replaces & < > " ' by &amp; &lt; &gt; &quot; &apos;; every other byte (UTF-8 included)
// is kept as it is.
std::string xml_escape(std::string_view text);

}  // namespace sf::io
