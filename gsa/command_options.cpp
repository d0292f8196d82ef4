#include "gsa/command_options.hpp"

#include <algorithm>

#include "common/core/error.hpp"
#include "common/io/grid_file.hpp"

namespace sf::gsa {

std::map<std::string, std::string> parse_column_map(const std::string& text) {
  std::map<std::string, std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    const std::size_t eq = item.find('=');
    if (item.empty() || eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw UsageError("--columns: expected NAME=COLUMN pairs separated by commas (e.g. X=x0,u=disp_x), found '" +
                       item + "'");
    const std::string key = item.substr(0, eq);
    if (!io::is_grid_column_key(key))
      throw UsageError("--columns: unknown name '" + key + "' (expected one of id X Y Z x y z u v w i j)");
    out[key] = item.substr(eq + 1);
    start = end + 1;
  }
  return out;
}

char parse_delimiter(const std::string& text) {
  if (text == "tab" || text == "\\t") return '\t';
  if (text == "comma") return ',';
  if (text == "semicolon") return ';';
  if (text == "space") return ' ';
  if (text.size() == 1) return text[0];
  throw UsageError("--delimiter: expected one character or tab/comma/semicolon/space, found '" + text + "'");
}

}  // namespace sf::gsa
