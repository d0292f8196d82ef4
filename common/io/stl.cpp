#include "common/io/stl.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::io {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kFacetBytes = 50;

// Welds vertices with bit-identical coordinates and drops facets of zero area.
class MeshBuilder {
 public:
  explicit MeshBuilder(TriangleMesh& mesh) : mesh_(mesh) {}

  // False when the facet has zero area (dropped).
  bool add_facet(const std::array<Vec3, 3>& v) {
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    const double scale = std::max({(v[1] - v[0]).squaredNorm(), (v[2] - v[0]).squaredNorm(), 1e-300});
    if (!(n.norm() > 1e-14 * scale)) {
      ++mesh_.dropped_degenerate;
      return false;
    }
    std::array<Index, 3> t{};
    for (int i = 0; i < 3; ++i) t[i] = vertex(v[i]);
    mesh_.triangles.push_back(t);
    return true;
  }

  void finish() {
    mesh_.vertices.resize(static_cast<Index>(points_.size()), 3);
    for (std::size_t i = 0; i < points_.size(); ++i) mesh_.vertices.row(static_cast<Index>(i)) = points_[i].transpose();
  }

 private:
  Index vertex(const Vec3& p) {
    const auto key = std::make_tuple(p.x(), p.y(), p.z());
    const auto it = index_.find(key);
    if (it != index_.end()) return it->second;
    const Index id = static_cast<Index>(points_.size());
    points_.push_back(p);
    index_.emplace(key, id);
    return id;
  }

  TriangleMesh& mesh_;
  std::vector<Vec3> points_;
  std::map<std::tuple<double, double, double>, Index> index_;
};

// ASCII tokens with their line and column (1-based).
struct Token {
  std::string text;
  int line = 0;
  int column = 0;
};

class AsciiReader {
 public:
  AsciiReader(const std::string& bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  void read(TriangleMesh& mesh) {
    MeshBuilder builder(mesh);
    Token t = next();
    if (!is(t, "solid")) fail(t, "expected 'solid' at the start of an ASCII STL file", t);
    bool first_solid = true;
    while (true) {
      // The rest of the `solid` line is the name.
      const std::string name = rest_of_line();
      if (first_solid) mesh.name = name;
      first_solid = false;
      for (;;) {
        t = next();
        if (is(t, "endsolid")) {
          rest_of_line();
          break;
        }
        if (!is(t, "facet")) fail(t, "expected 'facet' or 'endsolid'", t);
        expect("normal");
        for (int i = 0; i < 3; ++i) number("facet normal component");
        expect("outer");
        expect("loop");
        std::array<Vec3, 3> v;
        for (int k = 0; k < 3; ++k) {
          expect("vertex");
          for (int i = 0; i < 3; ++i) v[k][i] = number("vertex coordinate");
        }
        expect("endloop");
        expect("endfacet");
        builder.add_facet(v);
      }
      t = next();
      if (t.text.empty()) break;
      if (!is(t, "solid")) fail(t, "expected 'solid' or the end of the file after 'endsolid'", t);
    }
    builder.finish();
  }

 private:
  [[noreturn]] void fail(const Token& at, const std::string& what, const Token& found) const {
    const std::string f = found.text.empty() ? "the end of the file" : "'" + found.text + "'";
    throw InputError(located_message(name_, at.line, at.column, what + ", found " + f));
  }

  static bool is(const Token& t, const char* word) {
    if (t.text.size() != std::strlen(word)) return false;
    for (std::size_t i = 0; i < t.text.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(t.text[i])) != word[i]) return false;
    return true;
  }

  void skip_blanks() {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) advance();
  }

  void advance() {
    if (bytes_[pos_] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    ++pos_;
  }

  Token next() {
    skip_blanks();
    Token t;
    t.line = line_;
    t.column = column_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) {
      t.text += bytes_[pos_];
      advance();
    }
    return t;
  }

  std::string rest_of_line() {
    std::string s;
    while (pos_ < bytes_.size() && bytes_[pos_] != '\n') {
      s += bytes_[pos_];
      advance();
    }
    const auto b = s.find_first_not_of(" \t\r");
    const auto e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }

  void expect(const char* word) {
    const Token t = next();
    if (!is(t, word)) fail(t, std::string("expected '") + word + "'", t);
  }

  double number(const char* what) {
    const Token t = next();
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(t.text.c_str(), &end);
    if (t.text.empty() || end != t.text.c_str() + t.text.size() || errno == ERANGE || !std::isfinite(v))
      fail(t, std::string("expected a finite number (") + what + ")", t);
    return v;
  }

  const std::string& bytes_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
};

std::uint32_t read_u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
  return v;
}

float read_f32(const std::string& b, std::size_t at) {
  const std::uint32_t bits = read_u32(b, at);
  float f = 0.0f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

std::string byte_message(const std::string& name, std::size_t byte, const std::string& what) {
  return name + ": byte " + std::to_string(byte) + ": " + what;
}

void read_binary(const std::string& bytes, const std::string& name, TriangleMesh& mesh) {
  const std::uint32_t count = read_u32(bytes, kHeaderBytes);
  const std::size_t expected = kHeaderBytes + 4 + kFacetBytes * static_cast<std::size_t>(count);
  if (bytes.size() != expected) {
    std::ostringstream os;
    os << "expected 84 + 50 x " << count << " = " << expected << " bytes for the " << count
       << " facets the binary header announces, found " << bytes.size();
    throw InputError(byte_message(name, kHeaderBytes, os.str()));
  }
  mesh.binary = true;
  std::string header = bytes.substr(0, kHeaderBytes);
  header.erase(std::find(header.begin(), header.end(), '\0'), header.end());
  const auto b = header.find_first_not_of(" \t\r\n");
  const auto e = header.find_last_not_of(" \t\r\n");
  mesh.name = b == std::string::npos ? std::string() : header.substr(b, e - b + 1);
  MeshBuilder builder(mesh);
  for (std::uint32_t f = 0; f < count; ++f) {
    const std::size_t at = kHeaderBytes + 4 + kFacetBytes * f;
    std::array<Vec3, 3> v;
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) {
        const std::size_t byte = at + 12 + 12 * static_cast<std::size_t>(k) + 4 * static_cast<std::size_t>(i);
        const double c = read_f32(bytes, byte);
        if (!std::isfinite(c))
          throw InputError(
              byte_message(name, byte, "vertex coordinate of facet " + std::to_string(f + 1) + " is not finite"));
        v[k][i] = c;
      }
    builder.add_facet(v);
  }
  builder.finish();
}

void write_u32(std::string& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b += static_cast<char>((v >> (8 * i)) & 0xffu);
}

void write_f32(std::string& b, double v) {
  const float f = static_cast<float>(v);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof f);
  write_u32(b, bits);
}

Vec3 facet_normal(const TriangleMesh& mesh, const std::array<Index, 3>& t) {
  const Vec3 a = mesh.vertices.row(t[0]).transpose(), b = mesh.vertices.row(t[1]).transpose(),
             c = mesh.vertices.row(t[2]).transpose();
  const Vec3 n = (b - a).cross(c - a);
  return n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3::Zero();
}

}  // namespace

TriangleMesh read_stl_bytes(const std::string& bytes, const std::string& name) {
  TriangleMesh mesh;
  const bool sized_as_binary =
      bytes.size() >= kHeaderBytes + 4 &&
      bytes.size() == kHeaderBytes + 4 + kFacetBytes * static_cast<std::size_t>(read_u32(bytes, kHeaderBytes));
  std::size_t first = 0;
  while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first]))) ++first;
  const bool starts_solid =
      bytes.size() >= first + 5 &&
      std::equal(bytes.begin() + static_cast<long>(first), bytes.begin() + static_cast<long>(first) + 5, "solid",
                 [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
  if (sized_as_binary) {
    read_binary(bytes, name, mesh);
  } else if (starts_solid) {
    AsciiReader(bytes, name).read(mesh);
  } else if (bytes.size() >= kHeaderBytes + 4) {
    read_binary(bytes, name, mesh);  // reports the size mismatch
  } else {
    throw InputError(byte_message(name, 0,
                                  "not an STL file: neither ASCII (starting with 'solid') nor binary (" +
                                      std::to_string(bytes.size()) + " bytes, fewer than the 84 of a header)"));
  }
  if (mesh.triangles.empty())
    throw InputError(name + ": no facet of positive area (" + std::to_string(mesh.dropped_degenerate) +
                     " degenerate facets)");
  return mesh;
}

TriangleMesh read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open STL file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return read_stl_bytes(ss.str(), path);
}

void write_stl_ascii(const std::string& path, const TriangleMesh& mesh) {
  std::ostringstream os;
  os.precision(17);
  os << "solid " << mesh.name << "\n";
  for (const auto& t : mesh.triangles) {
    const Vec3 n = facet_normal(mesh, t);
    os << "  facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n    outer loop\n";
    for (int k = 0; k < 3; ++k)
      os << "      vertex " << mesh.vertices(t[k], 0) << " " << mesh.vertices(t[k], 1) << " " << mesh.vertices(t[k], 2)
         << "\n";
    os << "    endloop\n  endfacet\n";
  }
  os << "endsolid " << mesh.name << "\n";
  write_file_atomic(path, os.str());
}

void write_stl_binary(const std::string& path, const TriangleMesh& mesh) {
  std::string b(kHeaderBytes, '\0');
  std::copy_n(mesh.name.begin(), std::min(mesh.name.size(), kHeaderBytes), b.begin());
  write_u32(b, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Vec3 n = facet_normal(mesh, t);
    for (int i = 0; i < 3; ++i) write_f32(b, n[i]);
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) write_f32(b, mesh.vertices(t[k], i));
    b += '\0';
    b += '\0';
  }
  write_file_atomic(path, b);
}

}  // namespace sf::io
