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
#include <tuple>
#include <unordered_set>

#include "common/core/error.hpp"

namespace sf::io {

namespace {

constexpr std::size_t kMaxLineBytes = (std::size_t{1} << 30) - 1;
// The header test looks at this many non-blank lines at most (preambles are short).
constexpr int kHeaderSearchLines = 1000;

bool is_blank(char c, char delimiter) { return (c == ' ' || c == '\t') && c != delimiter; }

bool equals_nan(std::string_view s) {
  return s.size() == 3 && (s[0] == 'n' || s[0] == 'N') && (s[1] == 'a' || s[1] == 'A') && (s[2] == 'n' || s[2] == 'N');
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
  throw InputError(
      located_message(file_name_, 0, 0, fmt::format("missing required column '{}' (found: {})", name, found)));
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
  const std::size_t begin = rows_[row].line_begin + c.offset + ((c.size_and_flags & kQuoted) ? 1 : 0);
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
  const std::string_view s = cell(row, col);
  // "1,25" in a file whose decimal separator is taken to be '.': say so.
  std::string hint;
  const auto comma = s.find(',');
  if (decimal_ == '.' && comma != std::string_view::npos && s.find(',', comma + 1) == std::string_view::npos) {
    std::string dotted(s);
    dotted[comma] = '.';
    double ignored = 0.0;
    if (parse_double(dotted, ignored)) hint = " (a decimal comma? read the file with ',' as the decimal separator)";
  }
  throw InputError(located_message(
      file_name_, line(row), static_cast<int>(col + 1),
      fmt::format("expected {} in column {}, found {}{}", what, column_label(col), quote_for_message(s), hint)));
}

double CsvTable::number(std::size_t row, std::size_t col, bool allow_missing) const {
  const std::string_view s = cell(row, col);
  double value = 0.0;
  if (decimal_ == ',') {
    std::string copy(s);
    std::replace(copy.begin(), copy.end(), ',', '.');
    if (copy.find(',') == std::string::npos && parse_double(copy, value)) return value;
  } else if (parse_double(s, value)) {
    return value;
  }
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

namespace {

// One line of the text: content [begin, end) without the line end; next = start of the
// following line.
struct LineSpan {
  std::size_t begin = 0, end = 0, next = 0;
};

LineSpan line_at(const std::string& text, std::size_t pos) {
  const char* nl = static_cast<const char*>(std::memchr(text.data() + pos, '\n', text.size() - pos));
  LineSpan l;
  l.begin = pos;
  l.next = nl ? static_cast<std::size_t>(nl - text.data()) + 1 : text.size();
  l.end = nl ? l.next - 1 : text.size();
  if (l.end > l.begin && text[l.end - 1] == '\r') --l.end;
  return l;
}

bool is_space_or_tab(char c) { return c == ' ' || c == '\t'; }

// Offset of the ']' closing the '[' at `open`, or npos when the line has none.
std::size_t closing_bracket(std::string_view line, std::size_t open) { return line.find(']', open + 1); }

// Splits a header line into trimmed, unquoted names (the same field rules as the data
// rows; with `brackets`, a delimiter inside [...] does not split). On a malformed quote,
// returns false with the 1-based field number and the problem.
bool split_names(std::string_view line, char delim, bool brackets, std::vector<std::string>& names, int& bad_field,
                 std::string& problem) {
  names.clear();
  const bool whitespace = delim == ' ';
  auto blank = [&](char c) { return whitespace ? is_space_or_tab(c) : is_blank(c, delim); };
  auto separator = [&](char c) { return whitespace ? is_space_or_tab(c) : c == delim; };
  std::size_t p = 0;
  const std::size_t n = line.size();
  while (p < n && blank(line[p])) ++p;
  for (;;) {
    while (!whitespace && p < n && blank(line[p])) ++p;
    std::string name;
    if (p < n && line[p] == '"') {
      std::size_t q = p + 1;
      for (;;) {
        if (q >= n) {
          bad_field = static_cast<int>(names.size() + 1);
          problem = "unterminated quoted field (a quoted field must end with '\"' on the same line)";
          return false;
        }
        if (line[q] == '"') {
          if (q + 1 < n && line[q + 1] == '"') {
            name += '"';
            q += 2;
            continue;
          }
          break;
        }
        name += line[q++];
      }
      p = q + 1;
      if (!whitespace)
        while (p < n && blank(line[p])) ++p;
      if (p < n && !separator(line[p])) {
        bad_field = static_cast<int>(names.size() + 1);
        problem = fmt::format("unexpected character '{}' after the closing quote", line[p]);
        return false;
      }
    } else {
      const std::size_t start = p;
      while (p < n && !separator(line[p])) {
        if (brackets && line[p] == '[') {
          const std::size_t close = closing_bracket(line, p);
          if (close != std::string_view::npos) {
            p = close + 1;
            continue;
          }
        }
        ++p;
      }
      std::size_t end = p;
      while (end > start && blank(line[end - 1])) --end;
      name.assign(line.substr(start, end - start));
    }
    names.push_back(std::move(name));
    if (whitespace) {
      while (p < n && is_space_or_tab(line[p])) ++p;
      if (p >= n) break;
    } else {
      if (p >= n) break;
      ++p;  // the delimiter; a field follows (possibly empty)
    }
  }
  return true;
}

// The delimiter of a header line by counting: the most frequent of ',', ';', tab outside
// quotes (and brackets); else ' ' when blanks split the line; else ','.
char count_delimiter(std::string_view line, bool brackets, char decimal) {
  std::size_t counts[3] = {0, 0, 0};
  constexpr char kCandidates[3] = {',', ';', '\t'};
  bool quoted = false;
  for (std::size_t p = 0; p < line.size(); ++p) {
    const char c = line[p];
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    if (brackets && c == '[') {
      const std::size_t close = closing_bracket(line, p);
      if (close != std::string_view::npos) {
        p = close;
        continue;
      }
    }
    for (int k = 0; k < 3; ++k)
      if (c == kCandidates[k] && !(c == ',' && decimal == ',')) ++counts[k];
  }
  int best = -1;
  for (int k = 0; k < 3; ++k)
    if (counts[k] > 0 && (best < 0 || counts[k] > counts[best])) best = k;
  if (best >= 0) return kCandidates[best];
  const auto first = line.find_first_not_of(" \t");
  const auto last = line.find_last_not_of(" \t");
  if (first != std::string_view::npos &&
      line.substr(first, last - first + 1).find_first_of(" \t") != std::string_view::npos)
    return ' ';
  return ',';
}

// True for a line of nothing but blanks and delimiters (",,,", as spreadsheets leave them).
bool only_blanks_and_delimiters(std::string_view line, char delim) {
  for (const char c : line) {
    if (is_space_or_tab(c)) continue;
    if (delim == kDetectDelimiter ? (c == ',' || c == ';') : c == delim) continue;
    return false;
  }
  return true;
}

// The line without its leading blanks and, when it starts with it, the comment character.
std::string_view without_comment_mark(std::string_view line, char comment) {
  std::size_t p = 0;
  while (p < line.size() && is_space_or_tab(line[p])) ++p;
  if (comment != '\0' && p < line.size() && line[p] == comment) ++p;
  return line.substr(p);
}

bool is_comment_line(std::string_view line, char comment) {
  std::size_t p = 0;
  while (p < line.size() && is_space_or_tab(line[p])) ++p;
  return comment != '\0' && p < line.size() && line[p] == comment;
}

}  // namespace

std::pair<std::size_t, std::int64_t> CsvTable::find_header(std::size_t pos, const CsvOptions& options) {
  const std::size_t size = text_.size();
  const std::string_view text(text_);
  std::int64_t line_no = 0;
  while (line_no < options.skip_lines && pos < size) {
    pos = line_at(text_, pos).next;
    ++line_no;
  }
  delimiter_ = options.delimiter == kDetectDelimiter ? ',' : options.delimiter;
  if (!options.has_header) return {pos, line_no};

  std::vector<std::string> names;
  int bad_field = 0;
  std::string problem;
  // Takes `content` (line `number`) as the header with delimiter `delim`.
  auto accept = [&](std::string_view content, std::int64_t number, char delim) {
    if (!split_names(content, delim, options.brackets_in_header, names, bad_field, problem))
      throw InputError(located_message(file_name_, static_cast<int>(number), bad_field, problem));
    // Hashed (linear in the fields): a header line may hold tens of thousands of names.
    std::unordered_set<std::string_view> seen;
    seen.reserve(names.size());
    for (std::size_t f = 0; f < names.size(); ++f) {
      if (!names[f].empty() && !seen.insert(names[f]).second)
        throw InputError(located_message(file_name_, static_cast<int>(number), static_cast<int>(f + 1),
                                         fmt::format("duplicate column name '{}'", names[f])));
    }
    names_ = names;
    n_columns_ = names_.size();
    header_line_ = static_cast<int>(number);
    delimiter_ = delim;
    while (!preamble_.empty() && preamble_.back().first >= header_line_) preamble_.pop_back();
  };
  auto delimiter_of = [&](std::string_view content) {
    return options.delimiter != kDetectDelimiter
               ? options.delimiter
               : count_delimiter(content, options.brackets_in_header, options.decimal);
  };
  // The delimiter for which `content` passes the header test, or '\0'.
  auto passing_delimiter = [&](std::string_view content) -> char {
    std::vector<std::string> trial;
    int f = 0;
    std::string why;
    const std::vector<char> candidates = options.delimiter != kDetectDelimiter ? std::vector<char>{options.delimiter}
                                                                               : std::vector<char>{',', ';', '\t', ' '};
    for (const char d : candidates) {
      if (d == ',' && options.decimal == ',') continue;
      if (split_names(content, d, options.brackets_in_header, trial, f, why) && options.header_test(trial)) return d;
    }
    return '\0';
  };

  if (options.header_line > 0) {
    while (line_no + 1 < options.header_line && pos < size) {
      const LineSpan l = line_at(text_, pos);
      const std::string_view content = text.substr(l.begin, l.end - l.begin);
      if (content.find_first_not_of(" \t") != std::string_view::npos)
        preamble_.emplace_back(static_cast<int>(line_no + 1), std::string(content));
      pos = l.next;
      ++line_no;
    }
    if (pos >= size)
      throw InputError(located_message(
          file_name_, 0, 0,
          fmt::format("the header line {} is past the end of the file ({} lines)", options.header_line, line_no)));
    const LineSpan l = line_at(text_, pos);
    const std::string_view content = without_comment_mark(text.substr(l.begin, l.end - l.begin), options.comment);
    accept(content, line_no + 1, delimiter_of(content));
    return {l.next, line_no + 1};
  }

  // The non-comment lines looked at, for the fallback when no line passes the test.
  std::vector<std::pair<LineSpan, std::int64_t>> kept;
  int searched = 0;
  while (pos < size && searched < kHeaderSearchLines) {
    const LineSpan l = line_at(text_, pos);
    const std::int64_t number = ++line_no;
    pos = l.next;
    const std::string_view line = text.substr(l.begin, l.end - l.begin);
    if (line.find_first_not_of(" \t") == std::string_view::npos) continue;
    const bool comment = is_comment_line(line, options.comment);
    if (!comment && only_blanks_and_delimiters(line, options.delimiter)) continue;
    if (!options.header_test) {
      if (!comment) {
        accept(line, number, delimiter_of(line));
        return {l.next, number};
      }
      preamble_.emplace_back(static_cast<int>(number), std::string(line));
      continue;
    }
    ++searched;
    const std::string_view content = comment ? without_comment_mark(line, options.comment) : line;
    if (const char d = passing_delimiter(content)) {
      bool take = !comment;
      if (comment) {
        // A commented header counts only when data follows it, not another comment or header.
        take = true;
        for (std::size_t q = l.next; q < size;) {
          const LineSpan m = line_at(text_, q);
          q = m.next;
          const std::string_view next = text.substr(m.begin, m.end - m.begin);
          if (next.find_first_not_of(" \t") == std::string_view::npos) continue;
          take = !is_comment_line(next, options.comment) && passing_delimiter(next) == '\0';
          break;
        }
      }
      if (take) {
        accept(content, number, d);
        return {l.next, number};
      }
    }
    if (!comment) kept.emplace_back(l, number);
    preamble_.emplace_back(static_cast<int>(number), std::string(line));
  }
  if (kept.empty())
    throw InputError(located_message(file_name_, 0, 0, "no header line (the file is empty or only comments)"));
  // No line passed: take the line that looks most like the header of a table (not all
  // numbers, as many fields as the next line, the most fields), so that the caller's
  // column lookup names what is missing from it; else the first kept line.
  std::size_t best = 0;
  std::size_t best_fields = 0;
  std::vector<std::string> fields, next_fields;
  for (std::size_t k = 0; k + 1 < kept.size(); ++k) {
    const std::string_view line = text.substr(kept[k].first.begin, kept[k].first.end - kept[k].first.begin);
    const std::string_view next = text.substr(kept[k + 1].first.begin, kept[k + 1].first.end - kept[k + 1].first.begin);
    const char d = delimiter_of(line);
    if (!split_names(line, d, options.brackets_in_header, fields, bad_field, problem) ||
        !split_names(next, d, options.brackets_in_header, next_fields, bad_field, problem))
      continue;
    const bool numbers = std::all_of(fields.begin(), fields.end(), [](const std::string& f) {
      double ignored = 0.0;
      return parse_double(f, ignored);
    });
    if (fields.size() > 1 && fields.size() == next_fields.size() && !numbers && fields.size() > best_fields) {
      best = k;
      best_fields = fields.size();
    }
  }
  const auto& [l, number] = kept[best];
  const std::string_view line = text.substr(l.begin, l.end - l.begin);
  accept(line, number, delimiter_of(line));
  return {l.next, number};
}

void CsvTable::parse(const CsvOptions& options) {
  const char* const text = text_.data();
  const std::size_t size = text_.size();
  std::size_t pos = 0;
  if (size >= 3 && std::memcmp(text, "\xEF\xBB\xBF", 3) == 0) pos = 3;
  decimal_ = options.decimal == kDetectDecimal ? '.' : options.decimal;

  std::int64_t line_no = 0;
  std::tie(pos, line_no) = find_header(pos, options);
  const char delim = delimiter_;
  const bool whitespace = delim == ' ';
  auto separator = [&](char c) { return whitespace ? is_space_or_tab(c) : c == delim; };
  auto blank = [&](char c) { return whitespace ? is_space_or_tab(c) : is_blank(c, delim); };

  // Reserve for the data rows from the number of line ends.
  const std::size_t n_lines_estimate = static_cast<std::size_t>(std::count(text + pos, text + size, '\n')) + 1;
  bool width_known = options.has_header;
  if (width_known) {
    cells_.reserve(n_lines_estimate * n_columns_);
    rows_.reserve(n_lines_estimate);
  }
  std::string unescaped;                                         // scratch for a quoted field with doubled quotes
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
    std::size_t p = line_begin;
    while (p < line_end && is_space_or_tab(text[p])) ++p;
    if (p == line_end) continue;  // blank line
    if (options.comment != '\0' && text[p] == options.comment) continue;
    if (!whitespace) p = line_begin;

    // Split the line into fields, appended to cells_.
    const std::size_t first_cell = cells_.size();
    row_escaped.clear();
    bool all_empty = true;
    std::size_t field = 0;
    for (;; ++field) {
      while (p < line_end && blank(text[p])) ++p;
      const std::size_t field_start = p;
      Cell cell{static_cast<std::uint32_t>(field_start - line_begin), 0};
      if (p < line_end && text[p] == '"') {
        const std::size_t content_begin = p + 1;
        std::size_t q = content_begin;
        bool escaped = false;
        std::size_t close = 0;
        for (;;) {
          const char* quote =
              q < line_end ? static_cast<const char*>(std::memchr(text + q, '"', line_end - q)) : nullptr;
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
        if (!whitespace) {
          while (p < line_end && blank(text[p])) ++p;
          if (p < line_end && text[p] != delim) {
            throw InputError(
                located_message(file_name_, line_int, static_cast<int>(field + 1),
                                fmt::format("unexpected character '{}' after the closing quote", text[p])));
          }
        } else if (p < line_end && !separator(text[p])) {
          throw InputError(located_message(file_name_, line_int, static_cast<int>(field + 1),
                                           fmt::format("unexpected character '{}' after the closing quote", text[p])));
        }
      } else {
        std::size_t field_end = line_end;
        if (whitespace) {
          field_end = p;
          while (field_end < line_end && !separator(text[field_end])) ++field_end;
        } else if (p < line_end) {
          const char* d = static_cast<const char*>(std::memchr(text + p, delim, line_end - p));
          if (d) field_end = static_cast<std::size_t>(d - text);
        }
        std::size_t content_end = field_end;
        while (content_end > field_start && blank(text[content_end - 1])) {
          --content_end;
        }
        cell.size_and_flags = static_cast<std::uint32_t>(content_end - field_start);
        if (content_end > field_start) all_empty = false;
        p = field_end;
      }
      cells_.push_back(cell);
      if (whitespace) {
        while (p < line_end && is_space_or_tab(text[p])) ++p;
        if (p >= line_end) break;
      } else if (p < line_end) {
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

    if (!width_known) {
      n_columns_ = n_fields;
      width_known = true;
      cells_.reserve(n_lines_estimate * n_columns_);
      rows_.reserve(n_lines_estimate);
    } else if (n_fields != n_columns_) {
      throw InputError(located_message(file_name_, line_int, 0,
                                       fmt::format("expected {} fields (as in the {}), found {}", n_columns_,
                                                   options.has_header ? "header" : "first row", n_fields)));
    }
    const std::size_t row_index = rows_.size();
    for (auto& [f, value] : row_escaped) {
      escaped_.emplace(row_index * n_columns_ + f, std::move(value));
    }
    rows_.push_back(Row{line_begin, line_no});
  }
  if (options.decimal == kDetectDecimal) decimal_ = detect_decimal();
}

char CsvTable::detect_decimal() const {
  if (delimiter_ == ',') return '.';
  bool comma = false;
  const std::size_t n = std::min<std::size_t>(rows_.size(), 200);
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t c = 0; c < n_columns_; ++c) {
      const std::string_view s = cell(r, c);
      double ignored = 0.0;
      const auto at = s.find(',');
      if (at == std::string_view::npos) {
        if (s.find('.') != std::string_view::npos && parse_double(s, ignored)) return '.';
      } else if (!comma && s.find(',', at + 1) == std::string_view::npos && s.find('.') == std::string_view::npos) {
        std::string dotted(s);
        dotted[at] = '.';
        comma = parse_double(dotted, ignored);
      }
    }
  }
  return comma ? ',' : '.';
}

CsvTable read_csv_string(std::string text, const std::string& name, const CsvOptions& options) {
  if (options.delimiter == '"' || options.delimiter == '\n' || options.delimiter == '\r' ||
      (options.comment != '\0' && options.comment == options.delimiter) ||
      (options.decimal != '.' && options.decimal != ',' && options.decimal != kDetectDecimal) ||
      (options.decimal == ',' && options.delimiter == ',') || options.skip_lines < 0 || options.header_line < 0 ||
      (options.header_line > 0 && options.header_line <= options.skip_lines)) {
    throw std::logic_error("read_csv: invalid delimiter/comment/decimal/skip_lines/header_line options");
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
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) {
    throw InputError(located_message(path, 0, 0, fmt::format("cannot open file ({})", std::strerror(errno))));
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
    throw InputError(located_message(path, 0, 0, fmt::format("cannot read file ({})", std::strerror(errno))));
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
    throw std::logic_error(fmt::format("CsvWriter: row has {} cells, header has {}", n_in_row_, n_columns_));
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
