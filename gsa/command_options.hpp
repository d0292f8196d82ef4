#pragma once
// The command layer of gsa: option texts of the command line turned into the fields of
// the library's option structs. Errors are sf::UsageError naming the flag
// ("--delimiter: expected one character or tab/comma/semicolon/space, found 'ab'").

#include <map>
#include <string>

namespace sf::gsa {

// "--columns" text "X=x0,Y=y0,u=disp_x" -> key -> column name (keys: io::kGridColumnKeys).
std::map<std::string, std::string> parse_column_map(const std::string& text);
// "--delimiter": one character, or "tab", "comma", "semicolon", "space".
char parse_delimiter(const std::string& text);

}  // namespace sf::gsa
