#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

using test::message_of;
using ::testing::HasSubstr;

TEST(IoCsv, ReadsHeaderCellsAndLines) {
  const CsvTable t = read_csv_string("id,X,Y\np1,1.5,-2\np2,3e2,.25\n", "grid.csv");
  EXPECT_EQ(t.file_name(), "grid.csv");
  ASSERT_EQ(t.n_columns(), 3u);
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.names(), (std::vector<std::string>{"id", "X", "Y"}));
  EXPECT_EQ(t.header_line(), 1);
  EXPECT_TRUE(t.has_column("X"));
  EXPECT_FALSE(t.has_column("x"));  // case-sensitive
  EXPECT_EQ(t.column_index("Y"), 2u);
  EXPECT_EQ(t.cell(1, 0), "p2");
  EXPECT_EQ(t.line(0), 2);
  EXPECT_EQ(t.line(1), 3);
  EXPECT_DOUBLE_EQ(t.number(0, 1), 1.5);
  EXPECT_DOUBLE_EQ(t.number(0, 2), -2.0);
  EXPECT_DOUBLE_EQ(t.number(1, 1), 300.0);
  EXPECT_DOUBLE_EQ(t.number(1, 2), 0.25);
  const Eigen::VectorXd x = t.numbers(1);
  EXPECT_EQ(x.size(), 2);
  EXPECT_DOUBLE_EQ(x[1], 300.0);
}

TEST(IoCsv, MalformedNumberReportsLineAndFieldColumn) {
  const CsvTable t = read_csv_string("id,X,Y,Z\np1,1,2,3\np2,4,abc,6\n", "grid.csv");
  const std::string msg = message_of<InputError>([&] { t.number(1, 2); });
  EXPECT_EQ(msg, "grid.csv:3:3: expected a number in column 'Y', found 'abc'");
  // The character column points at the field start: "p2,4," is 5 characters.
  EXPECT_EQ(t.char_column(1, 2), 6);
}

TEST(IoCsv, CharColumnCountsUtf8Characters) {
  const CsvTable t = read_csv_string("a,b\n\xC3\xA9t\xC3\xA9,  x\n", "u.csv");
  EXPECT_EQ(t.cell(0, 0), "\xC3\xA9t\xC3\xA9");
  EXPECT_EQ(t.char_column(0, 0), 1);
  EXPECT_EQ(t.char_column(0, 1), 7);  // "été,  " is 6 characters (8 bytes)
}

TEST(IoCsv, WrongFieldCountReportsLine) {
  const std::string msg = message_of<InputError>([] { read_csv_string("id,X,Y\np1,1,2\n\np2,1\n", "grid.csv"); });
  EXPECT_EQ(msg, "grid.csv:4: expected 3 fields (as in the header), found 2");
  const std::string more = message_of<InputError>([] { read_csv_string("id,X\np1,1,2\n", "g.csv"); });
  EXPECT_EQ(more, "g.csv:2: expected 2 fields (as in the header), found 3");
}

TEST(IoCsv, MissingColumnListsWhatWasFound) {
  const CsvTable t = read_csv_string("id,X,Y\n", "grid.csv");
  EXPECT_EQ(t.n_rows(), 0u);
  const std::string msg = message_of<InputError>([&] { t.column_index("Z"); });
  EXPECT_EQ(msg, "grid.csv: missing required column 'Z' (found: id, X, Y)");
  EXPECT_FALSE(t.find_column("Z").has_value());
}

TEST(IoCsv, CommentAndBlankLinesKeepLineNumbersTrue) {
  const std::string text =
      "# measured 2024-01-01\n"  // 1
      "\n"                       // 2
      "id,X\n"                   // 3
      "  # a comment\n"          // 4
      "p1,1\n"                   // 5
      "   \n"                    // 6
      ",\n"                      // 7: only delimiters, as spreadsheets leave them
      "p2,oops\n";               // 8
  const CsvTable t = read_csv_string(text, "c.csv");
  EXPECT_EQ(t.header_line(), 3);
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.line(0), 5);
  EXPECT_EQ(t.line(1), 8);
  EXPECT_EQ(message_of<InputError>([&] { t.number(1, 1); }),
            "c.csv:8:2: expected a number in column 'X', found 'oops'");
}

TEST(IoCsv, QuotedCellsWithDelimitersAndDoubledQuotes) {
  const std::string text =
      "id,\"note, long\",X\n"
      "\"a,b\",\"he said \"\"hi\"\"\",  \" 2.5 \"  \n"
      "\"\",\"\"\"\",3\n";
  const CsvTable t = read_csv_string(text, "q.csv");
  EXPECT_EQ(t.names()[1], "note, long");
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.cell(0, 0), "a,b");
  EXPECT_EQ(t.cell(0, 1), "he said \"hi\"");
  EXPECT_EQ(t.cell(0, 2), " 2.5 ");          // blanks inside quotes are kept...
  EXPECT_THROW(t.number(0, 2), InputError);  // ...so it is not a number
  EXPECT_EQ(t.cell(1, 0), "");
  EXPECT_EQ(t.cell(1, 1), "\"");
  EXPECT_DOUBLE_EQ(t.number(1, 2), 3.0);
  EXPECT_EQ(t.char_column(0, 2), 26);  // the opening quote, after two blanks
}

TEST(IoCsv, QuoteErrorsArePositioned) {
  EXPECT_EQ(message_of<InputError>([] { read_csv_string("a,b\n1,\"x\n", "q.csv"); }),
            "q.csv:2:2: unterminated quoted field (a quoted field must end with '\"' on the "
            "same line)");
  EXPECT_EQ(message_of<InputError>([] { read_csv_string("a,b\n\"x\"y,1\n", "q.csv"); }),
            "q.csv:2:1: unexpected character 'y' after the closing quote");
}

TEST(IoCsv, CrlfLineEndsAndBom) {
  const CsvTable t = read_csv_string("\xEF\xBB\xBFid,X\r\n# c\r\np1, 7 \r\np2,8", "w.csv");
  EXPECT_EQ(t.names()[0], "id");  // no BOM glued to the first name
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.cell(0, 1), "7");
  EXPECT_DOUBLE_EQ(t.number(1, 1), 8.0);  // last line without a line end
  EXPECT_EQ(t.line(0), 3);
  EXPECT_EQ(t.line(1), 4);
  EXPECT_EQ(t.char_column(0, 0), 1);
}

TEST(IoCsv, NanAndMissingCells) {
  const CsvTable t = read_csv_string("id,x\np1,\np2,nan\np3,NaN\np4,NA\n", "n.csv");
  EXPECT_TRUE(std::isnan(t.number(0, 1, true)));
  EXPECT_TRUE(std::isnan(t.number(1, 1, true)));
  EXPECT_TRUE(std::isnan(t.number(2, 1, true)));
  EXPECT_TRUE(t.is_missing(0, 1));
  EXPECT_TRUE(t.is_missing(2, 1));
  EXPECT_FALSE(t.is_missing(3, 1));
  EXPECT_EQ(message_of<InputError>([&] { t.number(0, 1, false); }),
            "n.csv:2:2: expected a number in column 'x', found ''");
  EXPECT_EQ(message_of<InputError>([&] { t.number(1, 1, false); }),
            "n.csv:3:2: expected a number in column 'x', found 'nan'");
  EXPECT_EQ(message_of<InputError>([&] { t.number(3, 1, true); }),
            "n.csv:5:2: expected a number in column 'x', found 'NA'");
}

TEST(IoCsv, NumberParsingIsStrict) {
  const CsvTable t =
      read_csv_string("v\n1.5e3\n-0.5\n+2\n1e-310\n\"1,5\"\ninf\n-inf\n1e400\n0x10\n1.5abc\n1 2\n-\n.\n+-1\n", "s.csv");
  EXPECT_DOUBLE_EQ(t.number(0, 0), 1500.0);
  EXPECT_DOUBLE_EQ(t.number(1, 0), -0.5);
  EXPECT_DOUBLE_EQ(t.number(2, 0), 2.0);
  EXPECT_GT(t.number(3, 0), 0.0);  // denormal, not an error
  for (std::size_t r = 4; r < t.n_rows(); ++r) {
    EXPECT_THROW(t.number(r, 0, true), InputError) << "row " << r << ": '" << t.cell(r, 0) << "'";
  }
}

TEST(IoCsv, IntegerParsing) {
  const CsvTable t = read_csv_string("i,j\n3,-4\n+5,1.0\n", "i.csv");
  EXPECT_EQ(t.integer(0, 0), 3);
  EXPECT_EQ(t.integer(0, 1), -4);
  EXPECT_EQ(t.integer(1, 0), 5);
  EXPECT_EQ(message_of<InputError>([&] { t.integer(1, 1); }),
            "i.csv:3:2: expected an integer in column 'j', found '1.0'");
}

TEST(IoCsv, HeaderProblems) {
  EXPECT_EQ(message_of<InputError>([] { read_csv_string("id,x,id\n", "h.csv"); }),
            "h.csv:1:3: duplicate column name 'id'");
  EXPECT_EQ(message_of<InputError>([] { read_csv_string("# only a comment\n\n", "h.csv"); }),
            "h.csv: no header line (the file is empty or only comments)");
}

TEST(IoCsv, NoHeaderAndTabDelimiter) {
  CsvOptions options;
  options.has_header = false;
  options.delimiter = '\t';
  const CsvTable t = read_csv_string("1\t2\t\n4\t x\t6\n", "t.tsv", options);
  EXPECT_TRUE(t.names().empty());
  ASSERT_EQ(t.n_columns(), 3u);
  EXPECT_EQ(t.cell(0, 2), "");
  EXPECT_EQ(t.cell(1, 1), "x");  // tabs delimit; spaces are still trimmed
}

// Names as a measuring system writes them: a header found by the names it must hold,
// after a preamble of other tables; the delimiter found from it.
TEST(IoCsv, HeaderSearchSkipsAPreambleAndFindsTheDelimiter) {
  const std::string text =
      "Project: plate 7\n"           // 1
      "Stage;Time [s];Force [kN]\n"  // 2: another table first
      "12;24.0;18.5\n"               // 3
      "\n"                           // 4
      "id; x [mm]; y [mm]\n"         // 5: the header
      "p1; 1.5; 2\n"                 // 6
      "# a comment\n"                // 7
      "p2; 3; 4\n";                  // 8
  CsvOptions o;
  o.delimiter = kDetectDelimiter;
  o.header_test = [](const std::vector<std::string>& names) {
    return std::find(names.begin(), names.end(), "id") != names.end();
  };
  const CsvTable t = read_csv_string(text, "gom.csv", o);
  EXPECT_EQ(t.header_line(), 5);
  EXPECT_EQ(t.delimiter(), ';');
  EXPECT_EQ(t.names(), (std::vector<std::string>{"id", "x [mm]", "y [mm]"}));
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.line(1), 8);
  EXPECT_DOUBLE_EQ(t.number(0, 1), 1.5);
  ASSERT_EQ(t.preamble().size(), 3u);  // lines 1-3, not the blank line
  EXPECT_EQ(t.preamble()[1], (std::pair<int, std::string>{2, "Stage;Time [s];Force [kN]"}));
}

TEST(IoCsv, WithoutAPassingLineTheFirstKeptLineIsTheHeader) {
  CsvOptions o;
  o.delimiter = kDetectDelimiter;
  o.header_test = [](const std::vector<std::string>&) { return false; };
  const CsvTable t = read_csv_string("# c\na;b;c\n1;2;3\n", "f.csv", o);
  EXPECT_EQ(t.header_line(), 2);
  EXPECT_EQ(t.delimiter(), ';');  // by counting
  EXPECT_EQ(t.names(), (std::vector<std::string>{"a", "b", "c"}));
}

TEST(IoCsv, CommentedHeaderOverTheDataIsTheHeader) {
  CsvOptions o;
  o.delimiter = kDetectDelimiter;
  o.header_test = [](const std::vector<std::string>& names) { return names.size() == 3 && names[0] == "ID"; };
  const CsvTable t =
      read_csv_string("# exported 2024\n#   ID;  x_undef [mm];  u [mm]\n  1;  -8.5;  0.25\n", "n.txt", o);
  EXPECT_EQ(t.header_line(), 2);
  EXPECT_EQ(t.names(), (std::vector<std::string>{"ID", "x_undef [mm]", "u [mm]"}));
  ASSERT_EQ(t.n_rows(), 1u);
  EXPECT_DOUBLE_EQ(t.number(0, 2), 0.25);
  // A commented copy of the header just above the real one is not taken.
  const CsvTable u = read_csv_string("# ID;a;b\nID;a;b\n1;2;3\n", "n.txt", o);
  EXPECT_EQ(u.header_line(), 2);
  EXPECT_EQ(u.n_rows(), 1u);
}

TEST(IoCsv, SkipLinesAndAnExplicitHeaderLine) {
  const std::string text = "garbage,with,commas\n*** more, text\nid,v\np,1\n";
  CsvOptions o;
  o.skip_lines = 2;
  const CsvTable t = read_csv_string(text, "s.csv", o);
  EXPECT_EQ(t.header_line(), 3);
  EXPECT_EQ(t.line(0), 4);
  EXPECT_TRUE(t.preamble().empty());  // skipped lines are not kept
  CsvOptions h;
  h.header_line = 3;
  const CsvTable u = read_csv_string(text, "s.csv", h);
  EXPECT_EQ(u.names(), (std::vector<std::string>{"id", "v"}));
  EXPECT_EQ(u.preamble().size(), 2u);
  h.header_line = 9;
  EXPECT_THAT(message_of<InputError>([&] { read_csv_string(text, "s.csv", h); }),
              HasSubstr("s.csv: the header line 9 is past the end of the file (4 lines)"));
}

TEST(IoCsv, QuotedPaddedNamesAndBracketsHoldingTheDelimiter) {
  // VIC-3D pads quoted names with spaces; a unit in brackets may hold the delimiter.
  const CsvTable vic = read_csv_string(" \"X\",  \"Y\",  \"sigma\"\n0,0,-1\n", "vic.csv");
  EXPECT_EQ(vic.names(), (std::vector<std::string>{"X", "Y", "sigma"}));
  CsvOptions o;
  o.brackets_in_header = true;
  const CsvTable t = read_csv_string("id,eps [%, technical],\"a,b\"\np,1.5,2\n", "b.csv", o);
  EXPECT_EQ(t.names(), (std::vector<std::string>{"id", "eps [%, technical]", "a,b"}));
  EXPECT_DOUBLE_EQ(t.number(0, 1), 1.5);
  // An unclosed bracket is an ordinary character.
  const CsvTable u = read_csv_string("id,a [mm,b\np,1,2\n", "b.csv", o);
  EXPECT_EQ(u.names(), (std::vector<std::string>{"id", "a [mm", "b"}));
}

TEST(IoCsv, BlankRunsDelimitWithDelimiterSpace) {
  CsvOptions o;
  o.delimiter = ' ';
  const CsvTable t = read_csv_string("  SUBSET_ID  X\tY\n0   1.5e0 -2\n  1 \"a b\"   3\n", "d.txt", o);
  EXPECT_EQ(t.names(), (std::vector<std::string>{"SUBSET_ID", "X", "Y"}));
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_DOUBLE_EQ(t.number(0, 1), 1.5);
  EXPECT_DOUBLE_EQ(t.number(0, 2), -2.0);
  EXPECT_EQ(t.cell(1, 1), "a b");
  EXPECT_EQ(t.char_column(1, 2), 13);
  // Detected when nothing else splits the header.
  CsvOptions d;
  d.delimiter = kDetectDelimiter;
  EXPECT_EQ(read_csv_string("a  b c\n1 2 3\n", "w.txt", d).delimiter(), ' ');
  EXPECT_EQ(read_csv_string("a\tb c\n1\t2 3\n", "w.txt", d).delimiter(), '\t');
}

TEST(IoCsv, DecimalComma) {
  CsvOptions o;
  o.delimiter = ';';
  o.decimal = ',';
  const CsvTable t = read_csv_string("a;b\n1,25;-3e-1\n", "de.csv", o);
  EXPECT_DOUBLE_EQ(t.number(0, 0), 1.25);
  EXPECT_DOUBLE_EQ(t.number(0, 1), -0.3);
  // Read with the default '.', the message says what the cell looks like.
  CsvOptions dot;
  dot.delimiter = ';';
  const CsvTable u = read_csv_string("a;b\n1,25;2\n", "de.csv", dot);
  EXPECT_EQ(message_of<InputError>([&] { u.number(0, 0); }),
            "de.csv:2:1: expected a number in column 'a', found '1,25' (a decimal comma? read the file with ',' as "
            "the decimal separator)");
}

TEST(IoCsv, ThreeDigitExponents) {
  const CsvTable t = read_csv_string("x\n6.68633E-001\n-2.3296E+000\n", "m.csv");
  EXPECT_DOUBLE_EQ(t.number(0, 0), 0.668633);
  EXPECT_DOUBLE_EQ(t.number(1, 0), -2.3296);
}

TEST(IoCsv, FileReadingAndMissingFile) {
  test::ScratchDir dir;
  test::write_text(dir.path() / "g.csv", "id,X\np,1\n");
  const CsvTable t = read_csv(dir.file("g.csv"));
  EXPECT_EQ(t.file_name(), dir.file("g.csv"));
  EXPECT_DOUBLE_EQ(t.number(0, 1), 1.0);
  const std::string missing = dir.file("absent.csv");
  EXPECT_THAT(message_of<InputError>([&] { read_csv(missing); }), HasSubstr(missing + ": cannot open file"));
  EXPECT_THAT(message_of<InputError>([&] { read_csv(dir.path().string()); }), HasSubstr("cannot open file"));
}

TEST(IoCsvWriter, RoundTripsDoublesExactly) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<std::vector<double>> rows;
  for (int r = 0; r < 200; ++r) {
    const double scale = std::pow(10.0, (r % 41) - 20);
    rows.push_back({uniform(rng) * scale, uniform(rng), 1.0 / 3.0, -0.0, std::numeric_limits<double>::denorm_min(),
                    std::numeric_limits<double>::max()});
  }
  rows[7][1] = std::numeric_limits<double>::quiet_NaN();
  std::ostringstream out;
  CsvWriter w(out, {"a", "b", "c", "d", "e", "f"});
  for (const auto& row : rows) w.write_row(row);

  const CsvTable t = read_csv_string(out.str(), "w.csv");
  ASSERT_EQ(t.n_rows(), rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      const double back = t.number(r, c, true);
      if (std::isnan(rows[r][c])) {
        EXPECT_TRUE(std::isnan(back));
        EXPECT_EQ(t.cell(r, c), "");
      } else {
        EXPECT_EQ(back, rows[r][c]) << "row " << r << " column " << c;
      }
    }
  }
}

TEST(IoCsvWriter, QuotesWhereNeededAndKeepsEmptyRows) {
  std::ostringstream out;
  CsvWriter w(out, {"id", "status", "v"});
  w.begin_row().add("#1").add("a, b").add(2).end_row();
  w.begin_row().add(" pad").add("say \"x\"").add(std::size_t{7}).end_row();
  w.begin_row().add("").add("").add(std::nan("")).end_row();  // all empty
  w.begin_row().add("plain").add(std::string("ok")).add(0.1).end_row();
  EXPECT_EQ(out.str(),
            "id,status,v\n"
            "\"#1\",\"a, b\",2\n"
            "\" pad\",\"say \"\"x\"\"\",7\n"
            "\"\",,\n"
            "plain,ok,0.1\n");
  const CsvTable t = read_csv_string(out.str(), "w.csv");
  ASSERT_EQ(t.n_rows(), 4u);
  EXPECT_EQ(t.cell(0, 0), "#1");
  EXPECT_EQ(t.cell(0, 1), "a, b");
  EXPECT_EQ(t.cell(1, 0), " pad");
  EXPECT_EQ(t.cell(1, 1), "say \"x\"");
  EXPECT_EQ(t.cell(2, 0), "");
  EXPECT_EQ(t.cell(3, 1), "ok");
}

TEST(IoCsvWriter, WrongCellCountIsALogicError) {
  std::ostringstream out;
  CsvWriter w(out, {"a", "b"});
  EXPECT_THROW(w.write_row({1.0}), std::logic_error);
  CsvWriter w2(out, {"a"});
  w2.begin_row().add(1.0);
  EXPECT_THROW(w2.add(2.0), std::logic_error);
}

}  // namespace
}  // namespace sf::io
