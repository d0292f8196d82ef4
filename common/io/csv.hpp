#pragma once
// CSV reading with precise error positions, and a round-trip-exact CSV writer.
//
// Reading rules (CONTRACT.md, grid file):
//  - UTF-8; a leading byte-order mark is ignored. Line ends "\n" or "\r\n".
//  - A line whose first non-blank character is the comment character is skipped; so is a
//    blank line and a line holding nothing but delimiters and blanks (",,,", as spreadsheets
//    leave them). Skipped lines still count: line numbers always match the file.
//  - The first kept line is the header when CsvOptions::has_header (column order is free,
//    names are case-sensitive). Every later kept line must have as many fields as the header
//    (without a header: as the first kept line).
//  - Spaces and tabs around a field are trimmed (tabs are kept when the delimiter is a tab).
//  - A field may be double-quoted: it may then hold delimiters, surrounding blanks and
//    doubled quotes ("" -> "). A quoted field must close on the same line.
//
// Files written by measuring systems need more (CsvOptions): a preamble of any content
// before the header (skip_lines, or the header found by a test on its names), a header
// that is itself a comment line ("#  ID; x [mm]; ..."), names with a unit in brackets that
// holds the delimiter ("eps [%, technical]"), the delimiter found from the header, fields
// separated by runs of blanks (delimiter ' '), and a decimal comma.
// Positions in messages: "FILE:LINE:COLUMN: ..." where LINE is the 1-based line of the file
// and COLUMN is the 1-based FIELD NUMBER in that row (not a character offset). The
// character column of a field, counted in UTF-8 characters, is available from
// CsvTable::char_column() for callers that want to point at it.
//
// Storage: the table keeps the file text in one buffer and each cell as offsets into it,
// so reading 1e6 rows x 8 columns takes a fraction of a second and cells are string_views.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sf::io {

// CsvOptions::delimiter value: find the delimiter from the header line.
inline constexpr char kDetectDelimiter = '\0';
// CsvOptions::decimal value: find the decimal separator from the data rows.
inline constexpr char kDetectDecimal = '\0';

struct CsvOptions {
  // The field separator. ' ' means runs of blanks (spaces and tabs; a line's leading and
  // trailing blanks are ignored, so no field is empty). kDetectDelimiter: with a
  // header_test, the first of ',', ';', tab, ' ' for which the header passes it; otherwise
  // the most frequent of ',', ';', tab outside quotes in the header line, else ' ' when
  // that splits the line, else ','.
  char delimiter = ',';
  char comment = '#';  // '\0': no comment lines
  bool has_header = true;
  // Lines 1..skip_lines of the file are not read at all (a preamble of any content).
  int skip_lines = 0;
  // > 0: the header is this line of the file (1-based), whatever it holds; a comment
  // character in front of its first name is removed. Lines before it are not read.
  int header_line = 0;
  // The header search: when set (and header_line is 0), the header is the first line
  // after skip_lines whose names pass the test. A comment line is tried too, without its
  // comment character, and is taken when the next non-blank line is neither a comment nor
  // a header that passes (a commented header over the data). Lines before the header are a
  // preamble and not read. The search looks at the first 1000 non-blank lines. When no
  // line passes, the header is the line that looks most like a table's (not all numbers,
  // as many fields as the next line, the most fields; else the first kept line), so that
  // the caller's column lookup reports what it found there.
  std::function<bool(const std::vector<std::string>& names)> header_test;
  // In the header only: a delimiter inside [...] does not split ("eps [%, technical]").
  bool brackets_in_header = false;
  // The decimal separator of numbers: '.' or ',' (then the delimiter cannot be ',').
  // kDetectDecimal: ',' when the delimiter is not ',' and the first 200 data rows hold a
  // number that reads only with a decimal comma ("1,25") and none written with a point
  // ("1.25"); else '.'. CsvTable::decimal() says which.
  char decimal = '.';
};

class CsvTable {
 public:
  CsvTable() = default;

  // File name used in messages (the path as given, or the name passed to read_csv_string).
  const std::string& file_name() const { return file_name_; }

  // Header names in file order; the column number of names()[c] is c + 1.
  // Empty when the table was read without a header.
  const std::vector<std::string>& names() const { return names_; }
  std::size_t n_columns() const { return n_columns_; }
  std::size_t n_rows() const { return rows_.size(); }
  // 1-based line number of the header in the file (0 without a header).
  int header_line() const { return header_line_; }
  // The delimiter used (the one found, with kDetectDelimiter).
  char delimiter() const { return delimiter_; }
  // The decimal separator used (the one found, with kDetectDecimal).
  char decimal() const { return decimal_; }
  // The non-blank lines before the header (comments and preamble), as written, with
  // their 1-based line numbers; lines dropped by skip_lines are not kept.
  const std::vector<std::pair<int, std::string>>& preamble() const { return preamble_; }

  bool has_column(std::string_view name) const { return find_column(name).has_value(); }
  // 0-based column index of `name`, or nothing.
  std::optional<std::size_t> find_column(std::string_view name) const;
  // 0-based column index of `name`; throws sf::InputError
  // "FILE: missing required column 'X' (found: a, b, c)".
  std::size_t column_index(std::string_view name) const;
  // Name of column `col` for messages: the header name, or "column N" without a header.
  std::string column_label(std::size_t col) const;

  // Raw cell text (trimmed, quotes removed). Valid while the table lives.
  // row in [0, n_rows()), col in [0, n_columns()).
  std::string_view cell(std::size_t row, std::size_t col) const;
  // 1-based line number of data row `row` in the file.
  int line(std::size_t row) const;
  // 1-based character column (UTF-8 characters) where field `col` of row `row` starts
  // (its opening quote for a quoted field).
  int char_column(std::size_t row, std::size_t col) const;

  // True for an empty cell or "nan" (any letter case): the "not digitised" marker.
  bool is_missing(std::size_t row, std::size_t col) const;

  // The cell as a number. The whole cell must be a decimal floating-point number
  // ("1.5e3", "-2", "+.5", "6.68633E-001"); "1,5" (unless CsvOptions::decimal is ','),
  // "0x1p3", "inf" and trailing text are rejected.
  // allow_missing: an empty cell or "nan"/"NaN" gives NaN; otherwise those are errors too.
  // Throws sf::InputError "FILE:LINE:COLUMN: expected a number in column 'NAME', found 'abc'".
  double number(std::size_t row, std::size_t col, bool allow_missing = false) const;
  // The cell as a decimal integer ("12", "-3", "+4"); throws sf::InputError
  // "FILE:LINE:COLUMN: expected an integer in column 'NAME', found '1.5'".
  long integer(std::size_t row, std::size_t col) const;
  // number() of every row of column `col` (n_rows()).
  Eigen::VectorXd numbers(std::size_t col, bool allow_missing = false) const;

 private:
  friend CsvTable read_csv_string(std::string text, const std::string& name, const CsvOptions& options);

  // A cell: offset of the field start from its line start, and the content size.
  // kQuoted: content starts one byte after the field start (the opening quote).
  // kEscaped: the content had doubled quotes; its unescaped text is in escaped_.
  struct Cell {
    std::uint32_t offset;
    std::uint32_t size_and_flags;
  };
  static constexpr std::uint32_t kQuoted = 1u << 31;
  static constexpr std::uint32_t kEscaped = 1u << 30;
  static constexpr std::uint32_t kSizeMask = kEscaped - 1;

  struct Row {
    std::size_t line_begin;  // byte offset of the line in text_
    std::int64_t line;       // 1-based line number
  };

  void parse(const CsvOptions& options);
  // Finds the header (CsvOptions: skip_lines, header_line, header_test), sets names_,
  // header_line_, delimiter_ and preamble_; returns the byte offset after the header line
  // and its line number, or (text size, lines) without a header.
  std::pair<std::size_t, std::int64_t> find_header(std::size_t pos, const CsvOptions& options);
  // The decimal separator of the data rows (CsvOptions::decimal == kDetectDecimal).
  char detect_decimal() const;
  [[noreturn]] void throw_bad_cell(std::size_t row, std::size_t col, const char* what) const;

  std::string file_name_;
  std::string text_;  // the whole file
  std::vector<std::string> names_;
  std::size_t n_columns_ = 0;
  int header_line_ = 0;
  char delimiter_ = ',';
  char decimal_ = '.';
  std::vector<std::pair<int, std::string>> preamble_;
  std::vector<Row> rows_;
  std::vector<Cell> cells_;                               // n_rows x n_columns, row-major
  std::unordered_map<std::size_t, std::string> escaped_;  // cell index -> unescaped text
};

// Reads a CSV file ("-": standard input, named "<stdin>" in messages). Throws sf::InputError
// "PATH: cannot open file (reason)" when it cannot be read, and the positioned errors
// described above when its content is malformed.
CsvTable read_csv(const std::string& path, const CsvOptions& options = {});
// Same from text in memory; `name` stands for the file name in messages.
CsvTable read_csv_string(std::string text, const std::string& name, const CsvOptions& options = {});

// Writes CSV to a stream: the header at construction, then one row per begin_row()/end_row().
// Numbers are written in the shortest form that reads back to the same double (fmt "{}");
// NaN is written as an empty cell; infinities as "inf"/"-inf" (which CsvTable::number()
// rejects: keep them out of files meant to be read back). Strings are quoted when they hold the delimiter, a quote,
// surrounding blanks, a line break, or start with '#' (so the reader never takes them for a
// comment). Rows output by the writer read back to the same cells with the default options.
//
//   CsvWriter w(out, {"id", "x", "y"});
//   w.begin_row().add("p1").add(1.5).add(std::nan("")).end_row();
//   w.write_row({1.0, 2.0, 3.0});
class CsvWriter {
 public:
  CsvWriter(std::ostream& out, std::vector<std::string> header, char delimiter = ',');
  // More rows of a table whose header is written elsewhere (rows formatted in
  // parallel, then concatenated after the header).
  CsvWriter(std::ostream& out, std::size_t n_columns, char delimiter = ',');

  std::size_t n_columns() const { return n_columns_; }

  CsvWriter& begin_row();
  CsvWriter& add(double value);
  CsvWriter& add(std::string_view text);
  CsvWriter& add(const char* text) { return add(std::string_view(text)); }
  CsvWriter& add(const std::string& text) { return add(std::string_view(text)); }
  template <class T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, int> = 0>
  CsvWriter& add(T value) {
    return add_integer(static_cast<long long>(value));
  }
  // Ends the row; throws std::logic_error unless it had exactly n_columns() cells.
  void end_row();
  // A whole row of numbers (size n_columns()).
  void write_row(const std::vector<double>& values);

 private:
  CsvWriter& add_integer(long long value);
  void add_raw(std::string_view text, bool quote);

  std::ostream& out_;
  char delimiter_;
  std::size_t n_columns_ = 0;
  std::size_t n_in_row_ = 0;
  bool in_row_ = false;
  bool row_all_empty_ = true;
  std::string row_;  // the row being built
};

}  // namespace sf::io
