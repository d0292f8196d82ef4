#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/core/error.hpp"
#include "common/io/json.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

using ::testing::HasSubstr;

TEST(IoJson, WritesPrettyWithNanAsNull) {
  test::ScratchDir dir;
  nlohmann::json j;
  j["rms"] = std::numeric_limits<double>::quiet_NaN();
  j["max"] = std::numeric_limits<double>::infinity();
  j["n"] = 3;
  write_json(dir.file("s.json"), j);
  const std::string text = test::read_text(dir.path() / "s.json");
  EXPECT_EQ(text, "{\n  \"max\": null,\n  \"n\": 3,\n  \"rms\": null\n}\n");
  const nlohmann::json back = read_json(dir.file("s.json"));
  EXPECT_TRUE(back["rms"].is_null());
  EXPECT_EQ(back["n"], 3);
}

TEST(IoJson, MatrixAsArrayOfRows) {
  Eigen::MatrixXd m(2, 3);
  m << 1, 2, 3, 4, 5, std::nan("");
  const nlohmann::json j = to_json(m);
  EXPECT_EQ(j.dump(), "[[1.0,2.0,3.0],[4.0,5.0,null]]");
  EXPECT_EQ(to_json(Eigen::MatrixXd(0, 3)).dump(), "[]");
  const Eigen::Vector3d v(0.5, 1.5, 2.5);
  EXPECT_EQ(to_json(v).dump(), "[[0.5],[1.5],[2.5]]");
}

TEST(IoJson, ReadErrorsArePositioned) {
  test::ScratchDir dir;
  test::write_text(dir.path() / "bad.json", "{\n  \"a\": 1,\n  \"b\": x\n}\n");
  EXPECT_THAT(test::message_of<InputError>([&] { read_json(dir.file("bad.json")); }),
              HasSubstr(dir.file("bad.json") + ":3:8: invalid JSON: "));
  EXPECT_THAT(test::message_of<InputError>([&] { read_json(dir.file("none.json")); }),
              HasSubstr(dir.file("none.json") + ": cannot open file"));
}

TEST(IoJson, WriteToMissingDirectoryThrowsWithPath) {
  test::ScratchDir dir;
  const std::string path = dir.file("no/such/dir/s.json");
  EXPECT_THAT(test::message_of<Error>([&] { write_json(path, nlohmann::json::object()); }),
              HasSubstr(path + ": cannot write file"));
}

}  // namespace
}  // namespace sf::io
