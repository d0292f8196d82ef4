#include "common/io/csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "common/core/error.hpp"

namespace sf::io {

namespace {

constexpr std::size_t kMaxLineBytes = (std::size_t{1} << 30) - 1;

bool is_blank(char c, char delimiter) { return (c == ' ' || c == '\t') && c != delimiter; }

bool equals_nan(std::string_view s) {
  return s.size() == 3 && (s[0] == 'n' || s[0] == 'N') && (s[1] == 'a' || s[1] == 'A') &&
         (s[2] == 'n' || s[2] == 'N');
}

// Strict decimal floating-point parse of the whole of `s`; false on anything else.
bool parse_double(std::string_view s, double& value) {
  if (s.empty()) return false;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  const bool plus = *first == '+';
  if (plus) ++first;
  if (first == last) return false;
  // from_chars also takes "inf", "nan" and "infinity": accept digits and '.' starts only.
  const char c0 = (*first == '-') ? (first + 1 < last ? first[1] : '\0') : *first;
  if (plus && *first == '-') return false;
  if (!((c0 >= '0' && c0 <= '9') || c0 == '.')) return false;
  const auto [ptr, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ptr != last) return false;
  if (ec == std::errc::result_out_of_range) {
    // Underflow gives a denormal or zero with strtod; overflow is rejected.
    const std::string copy(first, last);
    char* end = nullptr;
    value = std::strtod(copy.c_str(), &end);
    return end == copy.c_str() + copy.size() && std::isfinite(value);
  }
  return ec == std::errc() && std::isfinite(value);
}

bool parse_long(std::string_view s, long& value) {
  if (s.empty()) return false;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (*first == '+') {
    ++first;
    if (first == last || *first == '-') return false;
  }
  const auto [ptr, ec] = std::from_chars(first, last, value, 10);
  return ec == std::errc() && ptr == last;
}

// Cell text for messages: at most 40 characters, on one line.
std::string quote_for_message(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out(s.substr(0, kMax));
  if (s.size() > kMax) out += "...";
  return "'" + out + "'";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// CsvTable

std::optional<std::size_t> CsvTable::find_column(std::string_view name) const {
  for (std::size_t c = 0; c < names_.size(); ++c) {
    if (names_[c] == name) return c;
  }
  return std::nullopt;
}

std::size_t CsvTable::column_index(std::string_view name) const {
  if (const auto c = find_column(name)) return *c;
  std::string found;
  for (std::size_t c = 0; c < names_.size(); ++c) {
    if (c > 0) found += ", ";
    found += names_[c];
  }
  throw InputError(located_message(
      file_name_, 0, 0, fmt::format("missing required column '{}' (found: {})", name, found)));
}

std::string CsvTable::column_label(std::size_t col) const {
  if (col < names_.size()) return "'" + names_[col] + "'";
  return "column " + std::to_string(col + 1);
}

std::string_view CsvTable::cell(std::size_t row, std::size_t col) const {
  SF_ASSERT(row < rows_.size() && col < n_columns_, "CSV cell index out of range");
  const std::size_t index = row * n_columns_ + col;
  const Cell& c = cells_[index];
  if (c.size_and_flags & kEscaped) return escaped_.at(index);
  const std::size_t begin =
      rows_[row].line_begin + c.offset + ((c.size_and_flags & kQuoted) ? 1 : 0);
  return std::string_view(text_).substr(begin, c.size_and_flags & kSizeMask);
}

int CsvTable::line(std::size_t row) const {
  SF_ASSERT(row < rows_.size(), "CSV row index out of range");
  return static_cast<int>(rows_[row].line);
}

int CsvTable::char_column(std::size_t row, std::size_t col) const {
  SF_ASSERT(row < rows_.size() && col < n_columns_, "CSV cell index out of range");
  const Cell& c = cells_[row * n_columns_ + col];
  const char* p = text_.data() + rows_[row].line_begin;
  int column = 1;
  for (std::uint32_t i = 0; i < c.offset; ++i) {
    // Count UTF-8 lead bytes only (continuation bytes are 10xxxxxx).
    if ((static_cast<unsigned char>(p[i]) & 0xC0) != 0x80) ++column;
  }
  return column;
}

bool CsvTable::is_missing(std::size_t row, std::size_t col) const {
  const std::string_view s = cell(row, col);
  return s.empty() || equals_nan(s);
}

void CsvTable::throw_bad_cell(std::size_t row, std::size_t col, const char* what) const {
  throw InputError(
      located_message(file_name_, line(row), static_cast<int>(col + 1),
                      fmt::format("expected {} in column {}, found {}", what, column_label(col),
                                  quote_for_message(cell(row, col)))));
}

double CsvTable::number(std::size_t row, std::size_t col, bool allow_missing) const {
  const std::string_view s = cell(row, col);
  double value = 0.0;
  if (parse_double(s, value)) return value;
  if (allow_missing && (s.empty() || equals_nan(s))) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  throw_bad_cell(row, col, "a number");
}

long CsvTable::integer(std::size_t row, std::size_t col) const {
  long value = 0;
  if (parse_long(cell(row, col), value)) return value;
  throw_bad_cell(row, col, "an integer");
}

Eigen::VectorXd CsvTable::numbers(std::size_t col, bool allow_missing) const {
  Eigen::VectorXd out(static_cast<Eigen::Index>(n_rows()));
  for (std::size_t r = 0; r < n_rows(); ++r) {
    out[static_cast<Eigen::Index>(r)] = number(r, col, allow_missing);
  }
  return out;
}

void CsvTable::parse(const CsvOptions& options) {
  const char delim = options.delimiter;
  const char* const text = text_.data();
  const std::size_t size = text_.size();
  std::size_t pos = 0;
  if (size >= 3 && std::memcmp(text, "\xEF\xBB\xBF", 3) == 0) pos = 3;

  // Reserve for the data rows from the number of line ends.
  const std::size_t n_lines_estimate =
      static_cast<std::size_t>(std::count(text + pos, text + size, '\n')) + 1;

  bool need_header = options.has_header;
  bool width_known = false;
  std::int64_t line_no = 0;
  std::string unescaped;  // scratch for a quoted field with doubled quotes
  std::vector<std::pair<std::size_t, std::string>> row_escaped;  // (field, text) of this row

  while (pos < size) {
    ++line_no;
    const char* nl = static_cast<const char*>(std::memchr(text + pos, '\n', size - pos));
    const std::size_t eol = nl ? static_cast<std::size_t>(nl - text) : size;
    std::size_t line_end = eol;
    if (line_end > pos && text[line_end - 1] == '\r') --line_end;
    const std::size_t line_begin = pos;
    pos = eol + 1;
    const int line_int = static_cast<int>(line_no);

    if (line_end - line_begin > kMaxLineBytes) {
      throw InputError(located_message(file_name_, line_int, 0, "line too long (more than 1 GiB)"));
    }

    // Comment line: first non-blank character is the comment character.
    {
      std::size_t p = line_begin;
      while (p < line_end && (text[p] == ' ' || text[p] == '\t')) ++p;
      if (p == line_end) continue;  // blank line
      if (options.comment != '\0' && text[p] == options.comment) continue;
    }

    // Split the line into fields, appended to cells_.
    const std::size_t first_cell = cells_.size();
    row_escaped.clear();
    bool all_empty = true;
    std::size_t p = line_begin;
    std::size_t field = 0;
    for (;; ++field) {
      while (p < line_end && is_blank(text[p], delim)) ++p;
      const std::size_t field_start = p;
      Cell cell{static_cast<std::uint32_t>(field_start - line_begin), 0};
      if (p < line_end && text[p] == '"') {
        const std::size_t content_begin = p + 1;
        std::size_t q = content_begin;
        bool escaped = false;
        std::size_t close = 0;
        for (;;) {
          const char* quote =
              q < line_end ? static_cast<const char*>(std::memchr(text + q, '"', line_end - q))
                           : nullptr;
          if (!quote) {
            throw InputError(located_message(file_name_, line_int, static_cast<int>(field + 1),
                                             "unterminated quoted field (a quoted field must "
                                             "end with '\"' on the same line)"));
          }
          const std::size_t at = static_cast<std::size_t>(quote - text);
          if (at + 1 < line_end && text[at + 1] == '"') {
            escaped = true;
            q = at + 2;
            continue;
          }
          close = at;
          break;
        }
        if (escaped) {
          unescaped.clear();
          for (std::size_t i = content_begin; i < close; ++i) {
            unescaped += text[i];
            if (text[i] == '"') ++i;  // skip the second quote of a pair
          }
          cell.size_and_flags = static_cast<std::uint32_t>(unescaped.size()) | kQuoted | kEscaped;
          row_escaped.emplace_back(field, unescaped);
        } else {
          cell.size_and_flags = static_cast<std::uint32_t>(close - content_begin) | kQuoted;
        }
        all_empty = false;
        p = close + 1;
        while (p < line_end && is_blank(text[p], delim)) ++p;
        if (p < line_end && text[p] != delim) {
          throw InputError(located_message(
              file_name_, line_int, static_cast<int>(field + 1),
              fmt::format("unexpected character '{}' after the closing quote", text[p])));
        }
      } else {
        const char* d = p < line_end
                            ? static_cast<const char*>(std::memchr(text + p, delim, line_end - p))
                            : nullptr;
        const std::size_t field_end = d ? static_cast<std::size_t>(d - text) : line_end;
        std::size_t content_end = field_end;
        while (content_end > field_start && is_blank(text[content_end - 1], delim)) {
          --content_end;
        }
        cell.size_and_flags = static_cast<std::uint32_t>(content_end - field_start);
        if (content_end > field_start) all_empty = false;
        p = field_end;
      }
      cells_.push_back(cell);
      if (p < line_end) {
        ++p;  // the delimiter; a field follows (possibly empty)
      } else {
        break;
      }
    }
    const std::size_t n_fields = field + 1;

    if (all_empty) {  // only delimiters and blanks
      cells_.resize(first_cell);
      continue;
    }

    if (need_header) {
      names_.reserve(n_fields);
      for (std::size_t f = 0; f < n_fields; ++f) {
        const Cell& c = cells_[first_cell + f];
        std::string name;
        if (c.size_and_flags & kEscaped) {
          for (const auto& [index, value] : row_escaped) {
            if (index == f) name = value;
          }
        } else {
          name.assign(text + line_begin + c.offset + ((c.size_and_flags & kQuoted) ? 1 : 0),
                      c.size_and_flags & kSizeMask);
        }
        if (!name.empty() && std::find(names_.begin(), names_.end(), name) != names_.end()) {
          throw InputError(located_message(file_name_, line_int, static_cast<int>(f + 1),
                                           fmt::format("duplicate column name '{}'", name)));
        }
        names_.push_back(std::move(name));
      }
      cells_.resize(first_cell);
      n_columns_ = n_fields;
      header_line_ = line_int;
      need_header = false;
      width_known = true;
      cells_.reserve(n_lines_estimate * n_columns_);
      rows_.reserve(n_lines_estimate);
      continue;
    }

    if (!width_known) {
      n_columns_ = n_fields;
      width_known = true;
      cells_.reserve(n_lines_estimate * n_columns_);
      rows_.reserve(n_lines_estimate);
    } else if (n_fields != n_columns_) {
      throw InputError(
          located_message(file_name_, line_int, 0,
                          fmt::format("expected {} fields (as in the {}), found {}", n_columns_,
                                      options.has_header ? "header" : "first row", n_fields)));
    }
    const std::size_t row_index = rows_.size();
    for (auto& [f, value] : row_escaped) {
      escaped_.emplace(row_index * n_columns_ + f, std::move(value));
    }
    rows_.push_back(Row{line_begin, line_no});
  }

  if (need_header) {
    throw InputError(
        located_message(file_name_, 0, 0, "no header line (the file is empty or only comments)"));
  }
}

CsvTable read_csv_string(std::string text, const std::string& name, const CsvOptions& options) {
  if (options.delimiter == '"' || options.delimiter == '\n' || options.delimiter == '\r' ||
      (options.comment != '\0' && options.comment == options.delimiter)) {
    throw std::logic_error("read_csv: invalid delimiter/comment options");
  }
  CsvTable table;
  table.file_name_ = name;
  table.text_ = std::move(text);
  table.parse(options);
  return table;
}

CsvTable read_csv(const std::string& path, const CsvOptions& options) {
  if (path == "-") {  // standard input (e.g. `gsa digitise ... -o - | gsa analyse - ...`)
    std::string text((std::istreambuf_iterator<char>(std::cin)), std::istreambuf_iterator<char>());
    if (std::cin.bad()) throw InputError("<stdin>: cannot read standard input");
    return read_csv_string(std::move(text), "<stdin>", options);
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(located_message(path, 0, 0, "cannot open file (it is a directory)"));
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    throw InputError(
        located_message(path, 0, 0, fmt::format("cannot open file ({})", std::strerror(errno))));
  }
  std::string text;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec) text.reserve(static_cast<std::size_t>(size) + 1);
  char buffer[1 << 16];
  for (;;) {
    const std::size_t n = std::fread(buffer, 1, sizeof buffer, file.get());
    text.append(buffer, n);
    if (n < sizeof buffer) break;
  }
  if (std::ferror(file.get())) {
    throw InputError(
        located_message(path, 0, 0, fmt::format("cannot read file ({})", std::strerror(errno))));
  }
  return read_csv_string(std::move(text), path, options);
}

// ---------------------------------------------------------------------------------------
// CsvWriter

CsvWriter::CsvWriter(std::ostream& out, std::vector<std::string> header, char delimiter)
    : out_(out), delimiter_(delimiter), n_columns_(header.size()) {
  if (header.empty()) throw std::logic_error("CsvWriter: empty header");
  begin_row();
  for (const auto& name : header) add(name);
  end_row();
}

CsvWriter::CsvWriter(std::ostream& out, std::size_t n_columns, char delimiter)
    : out_(out), delimiter_(delimiter), n_columns_(n_columns) {
  if (n_columns == 0) throw std::logic_error("CsvWriter: no columns");
}

CsvWriter& CsvWriter::begin_row() {
  if (in_row_) throw std::logic_error("CsvWriter: begin_row() inside a row");
  in_row_ = true;
  n_in_row_ = 0;
  row_all_empty_ = true;
  row_.clear();
  return *this;
}

void CsvWriter::add_raw(std::string_view text, bool quote) {
  if (!in_row_) throw std::logic_error("CsvWriter: add() outside begin_row()/end_row()");
  if (n_in_row_ == n_columns_) {
    throw std::logic_error(fmt::format("CsvWriter: more than {} cells in a row", n_columns_));
  }
  if (n_in_row_ > 0) row_ += delimiter_;
  ++n_in_row_;
  if (!text.empty() || quote) row_all_empty_ = false;
  if (!quote) {
    row_ += text;
    return;
  }
  row_ += '"';
  for (const char c : text) {
    if (c == '"') row_ += '"';
    row_ += c;
  }
  row_ += '"';
}

CsvWriter& CsvWriter::add(double value) {
  if (std::isnan(value)) {
    add_raw({}, false);
  } else {
    char buffer[64];
    const auto end = fmt::format_to(buffer, "{}", value);
    add_raw(std::string_view(buffer, static_cast<std::size_t>(end - buffer)), false);
  }
  return *this;
}

CsvWriter& CsvWriter::add_integer(long long value) {
  char buffer[32];
  const auto end = fmt::format_to(buffer, "{}", value);
  add_raw(std::string_view(buffer, static_cast<std::size_t>(end - buffer)), false);
  return *this;
}

CsvWriter& CsvWriter::add(std::string_view text) {
  bool quote = false;
  if (!text.empty()) {
    const char first = text.front();
    const char last = text.back();
    quote = first == ' ' || first == '\t' || last == ' ' || last == '\t' || first == '#' ||
            text.find_first_of(std::string{delimiter_, '"', '\n', '\r'}) != std::string::npos;
  }
  add_raw(text, quote);
  return *this;
}

void CsvWriter::end_row() {
  if (!in_row_) throw std::logic_error("CsvWriter: end_row() without begin_row()");
  if (n_in_row_ != n_columns_) {
    throw std::logic_error(
        fmt::format("CsvWriter: row has {} cells, header has {}", n_in_row_, n_columns_));
  }
  in_row_ = false;
  // A row of empty cells alone would read back as a blank line: quote its first cell.
  if (row_all_empty_) out_ << "\"\"";
  row_ += '\n';
  out_.write(row_.data(), static_cast<std::streamsize>(row_.size()));
}

void CsvWriter::write_row(const std::vector<double>& values) {
  begin_row();
  for (const double v : values) add(v);
  end_row();
}

}  // namespace sf::io
