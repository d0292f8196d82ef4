#include "common/io/json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::io {

void write_json(const std::string& path, const nlohmann::json& j) {
  // dump() writes NaN and infinities as null; replace invalid UTF-8 rather than throw.
  std::string text = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  text += '\n';
  write_file_atomic(path, text);
}

nlohmann::json read_json(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(located_message(path, 0, 0, "is a folder; expected a JSON file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(located_message(path, 0, 0, fmt::format("cannot open file ({})", std::strerror(errno))));
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based byte position just after the offending character.
    const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    int line = 1;
    int column = 1;
    for (std::size_t i = 0; i < end; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    std::string what = e.what();
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line 1, ...: why".
    if (const auto colon = what.find(": "); colon != std::string::npos) {
      what = what.substr(colon + 2);
    }
    throw InputError(located_message(path, line, column, "invalid JSON: " + what));
  } catch (const nlohmann::json::exception& e) {
    // out_of_range 406: "number overflow parsing '1e400'" (beyond the range of a double).
    std::string what = e.what();
    if (const auto bracket = what.find("] "); bracket != std::string::npos) what = what.substr(bracket + 2);
    throw InputError(located_message(path, 0, 0, "invalid JSON: " + what + " (numbers must lie within +-1.8e308)"));
  }
}

nlohmann::json to_json(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace sf::io
