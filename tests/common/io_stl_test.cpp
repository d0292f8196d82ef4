// Tests of the STL reader and writers (common/io/stl.hpp): round trips of both kinds,
// welding of shared vertices, dropping of degenerate facets, and errors that name the
// place in the STL file (line:column for ASCII, byte offset for binary).
#include "common/io/stl.hpp"

#include <gtest/gtest.h>

#include <string>

#include "common/core/error.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

using test::message_of;
using test::ScratchDir;

// A unit square in z = 0 as two facets sharing the diagonal (4 vertices welded).
TriangleMesh square() {
  TriangleMesh m;
  m.name = "square";
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

const char* kAscii =
    "solid plate\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 1 0 0\n"
    "      vertex 1 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 1 1 0\n"
    "      vertex 0 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "endsolid plate\n";

TEST(IoStl, ReadsAsciiAndWeldsSharedVertices) {
  const TriangleMesh m = read_stl_bytes(kAscii, "plate.stl");
  EXPECT_FALSE(m.binary);
  EXPECT_EQ(m.name, "plate");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.vertices.rows(), 4);  // six corners, two of them shared twice
  EXPECT_EQ(m.triangles[0][0], m.triangles[1][0]);
  EXPECT_EQ(m.triangles[0][2], m.triangles[1][1]);
}

TEST(IoStl, AsciiAndBinaryRoundTrip) {
  ScratchDir dir;
  const TriangleMesh m = square();
  write_stl_ascii(dir.file("a.stl"), m);
  write_stl_binary(dir.file("b.stl"), m);
  for (const char* f : {"a.stl", "b.stl"}) {
    const TriangleMesh r = read_stl(dir.file(f));
    EXPECT_EQ(r.binary, std::string(f) == "b.stl");
    EXPECT_EQ(r.name, "square");
    ASSERT_EQ(r.vertices.rows(), 4) << f;
    ASSERT_EQ(r.triangles.size(), 2u) << f;
    for (int t = 0; t < 2; ++t)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ((r.vertices.row(r.triangles[t][k]) - m.vertices.row(m.triangles[t][k])).norm(), 0.0) << f;
  }
}

TEST(IoStl, BinaryWhoseHeaderStartsWithSolidIsReadAsBinary) {
  ScratchDir dir;
  TriangleMesh m = square();
  m.name = "solid from a CAD exporter";
  write_stl_binary(dir.file("b.stl"), m);
  const TriangleMesh r = read_stl(dir.file("b.stl"));
  EXPECT_TRUE(r.binary);
  EXPECT_EQ(r.triangles.size(), 2u);
}

TEST(IoStl, DegenerateFacetsAreDroppedAndCounted) {
  TriangleMesh m = square();
  m.triangles.push_back({0, 1, 1});  // repeated vertex
  ScratchDir dir;
  write_stl_ascii(dir.file("a.stl"), m);
  const TriangleMesh r = read_stl(dir.file("a.stl"));
  EXPECT_EQ(r.triangles.size(), 2u);
  EXPECT_EQ(r.dropped_degenerate, 1);
}

TEST(IoStl, AsciiErrorsNameLineAndColumn) {
  std::string bad = kAscii;
  bad.replace(bad.find("vertex 1 0 0"), 6, "vertx ");  // line 5, column 7
  EXPECT_EQ(message_of<InputError>([&] { read_stl_bytes(bad, "die.stl"); }),
            "die.stl:5:7: expected 'vertex', found 'vertx'");
  std::string nan = kAscii;
  nan.replace(nan.find("vertex 1 1 0"), 12, "vertex 1 x 0");  // line 6, the y coordinate at column 16
  EXPECT_EQ(message_of<InputError>([&] { read_stl_bytes(nan, "die.stl"); }),
            "die.stl:6:16: expected a finite number (vertex coordinate), found 'x'");
  const std::string cut = std::string(kAscii).substr(0, std::string(kAscii).find("    endloop"));
  EXPECT_NE(message_of<InputError>([&] { read_stl_bytes(cut, "die.stl"); })
                .find("expected 'endloop', found the end "
                      "of the file"),
            std::string::npos);
  EXPECT_NE(message_of<InputError>([&] { read_stl_bytes("hello", "x.stl"); }).find("x.stl: byte 0: not an STL file"),
            std::string::npos);
  EXPECT_NE(message_of<InputError>([] { read_stl("/nonexistent/die.stl"); }).find("cannot open"), std::string::npos);
}

TEST(IoStl, BinaryErrorsNameTheByte) {
  ScratchDir dir;
  write_stl_binary(dir.file("b.stl"), square());
  std::string bytes = test::read_text(dir.path() / "b.stl");
  // Truncated: the header announces 2 facets (184 bytes).
  EXPECT_EQ(message_of<InputError>([&] { read_stl_bytes(bytes.substr(0, 150), "b.stl"); }),
            "b.stl: byte 80: expected 84 + 50 x 2 = 184 bytes for the 2 facets the binary header announces, found 150");
  // A NaN coordinate: facet 2, vertex 1, y (byte 84 + 50 + 12 + 4 = 150).
  for (int i = 0; i < 4; ++i) bytes[static_cast<std::size_t>(150 + i)] = static_cast<char>(0xff);
  EXPECT_EQ(message_of<InputError>([&] { read_stl_bytes(bytes, "b.stl"); }),
            "b.stl: byte 150: vertex coordinate of facet 2 is not finite");
}

}  // namespace
}  // namespace sf::io
