// gsa analyse --mesh: the user's own mesh file (gsa/mesh_file.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/core/error.hpp"
#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/mesh_file.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {
namespace {

using ::testing::HasSubstr;

std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "sf_mesh_file_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

// n x n quads over [-50, 50]^2 (the synthetic grids' blank), as JSON.
std::string square_mesh_json(int n) {
  std::string nodes, elements;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      nodes += (nodes.empty() ? "" : ",") + std::string("[") + std::to_string(-50.0 + 100.0 * i / n) + "," +
               std::to_string(-50.0 + 100.0 * j / n) + ",0]";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      elements += (elements.empty() ? "" : ",") + std::string("[") + std::to_string(a) + "," + std::to_string(a + 1) +
                  "," + std::to_string(a + n + 1) + "," + std::to_string(a + n + 2) + "]";
    }
  return "{\"nodes\": [" + nodes + "], \"elements\": [" + elements + "]}";
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(GsaMeshFile, UserQuadMeshAnalysesTheDomeAccurately) {
  const std::string path = write_temp("square6.json", square_mesh_json(6));
  std::vector<ExactStrain> exact;
  const GridData g = make_synthetic_grid(synthetic_case("dome"), {}, &exact);
  AnalyseOptions o;
  o.mesh.file = path;
  const AnalysisResult r = analyse(g, o);
  EXPECT_EQ(r.mesh.n_elements(), 36);
  const StrainError e = strain_error(g, r, exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms(), 1e-4) << "measured 2.0e-5 when written";
}

TEST(GsaMeshFile, ReadsCollapsedElements) {
  // A square split into a centre-fan of 4 collapsed elements around node 0.
  const std::string path = write_temp("fan.json",
                                      R"({"nodes": [[0,0,0], [10,0,0], [0,10,0], [-10,0,0], [0,-10,0]],
          "elements": [[0,0,1,2], [0,0,2,3], [0,0,3,4], [0,0,4,1]]})");
  const mesh::SurfaceMesh m = read_mesh_file(path);
  EXPECT_EQ(m.n_elements(), 4);
  for (Index e = 0; e < 4; ++e) EXPECT_EQ(m.element(e).shape, mesh::ElementShape::kCollapsed);
  EXPECT_TRUE(m.boundary_edges().size() == 4u);
}

TEST(GsaMeshFile, BadFilesAreNamed) {
  EXPECT_THAT(message_of([] { read_mesh_file("/nonexistent/mesh.json"); }), HasSubstr("cannot open"));
  const std::string a = write_temp("a.json", "{\"nodes\": [[0,0,0]], \"elements\": []}");
  EXPECT_THAT(message_of([&] { read_mesh_file(a); }), HasSubstr("at least 4 nodes"));
  const std::string b =
      write_temp("b.json", R"({"nodes": [[0,0,0],[1,0,0],[0,1,0],[1,1,0]], "elements": [[0,1,2,9]]})");
  EXPECT_THAT(message_of([&] { read_mesh_file(b); }), HasSubstr("node 9"));
  const std::string c =
      write_temp("c.json", R"({"nodes": [[0,0,0],[1,0,"x"],[0,1,0],[1,1,0]], "elements": [[0,1,2,3]]})");
  EXPECT_THAT(message_of([&] { read_mesh_file(c); }), HasSubstr("nodes[1][2]"));
  // Two elements with opposite xi1 directions.
  const std::string d = write_temp(
      "d.json", R"({"nodes": [[0,0,0],[1,0,0],[2,0,0],[0,1,0],[1,1,0],[2,1,0]], "elements": [[0,1,3,4],[2,1,5,4]]})");
  EXPECT_THAT(message_of([&] { read_mesh_file(d); }), HasSubstr("disagreeing xi directions"));
  const std::string f = write_temp("f.json", "{ not json");
  EXPECT_THAT(message_of([&] { read_mesh_file(f); }), HasSubstr("invalid JSON"));
  EXPECT_THAT(message_of([&] { read_mesh_file(f); }), HasSubstr("f.json:1:"));  // line and column
  // Issue 20: a number beyond a double and a folder were "internal error, please report".
  const std::string g =
      write_temp("g.json", R"({"nodes": [[0,0,1e400],[1,0,0],[0,1,0],[1,1,0]], "elements": [[0,1,3,2]]})");
  EXPECT_THAT(message_of([&] { read_mesh_file(g); }), HasSubstr("1e400"));
  const std::string folder = std::filesystem::path(f).parent_path().string();
  EXPECT_THAT(message_of([&] { read_mesh_file(folder); }), HasSubstr("is a folder"));
}

}  // namespace
}  // namespace sf::gsa
