// Tests of the 3-D view's page (gsa/view3d): the embedded data read back from the HTML
// (base64 Float32 arrays) against the analysis: marks where they were measured, surface
// fields that equal the exact strain, decimation under a vertex budget, every strains.csv
// column (numbers and categories) offered, the budget of mark values, a page that stays
// one self-contained file, and the triangle method refused. The browser side is tested by
// tests/gsa/view3d_browser.py (gsa.view.browser_*).

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "gsa/analysis.hpp"
#include "gsa/output.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/synthetic.hpp"
#include "gsa/view3d.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

fs::path test_dir(const std::string& name) {
  const fs::path d = fs::path(SF_BINARY_DIR) / "test_output" / "gsa_view3d" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

GridData analyse_case(const std::string& name, const fs::path& dir, Method method = Method::kSurface) {
  SyntheticGridOptions g;
  g.n = 9;
  g.spacing = 10;
  const GridData grid = make_synthetic_grid(synthetic_case(name), g);
  AnalyseOptions o;
  o.method = method;
  AnalysisResult r = method == Method::kSurface ? analyse(grid, o) : analyse_triangles(grid, o);
  io::AtomicOutputDir out(dir);
  write_results(out, grid, r, OutputOptions{}, RunInfo{"test", {name}});
  out.commit();
  return grid;
}

std::vector<float> floats(const std::string& b64) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : 63;
  };
  std::vector<unsigned char> bytes;
  for (std::size_t i = 0; i + 3 < b64.size(); i += 4) {
    const int v = (val(b64[i]) << 18) | (val(b64[i + 1]) << 12) | (b64[i + 2] == '=' ? 0 : val(b64[i + 2]) << 6) |
                  (b64[i + 3] == '=' ? 0 : val(b64[i + 3]));
    bytes.push_back(static_cast<unsigned char>(v >> 16));
    if (b64[i + 2] != '=') bytes.push_back(static_cast<unsigned char>(v >> 8));
    if (b64[i + 3] != '=') bytes.push_back(static_cast<unsigned char>(v));
  }
  std::vector<float> f(bytes.size() / 4);
  std::memcpy(f.data(), bytes.data(), f.size() * 4);
  return f;
}

nlohmann::json data_of(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"gsa-view-data\">";
  const auto a = html.find(open);
  EXPECT_NE(a, std::string::npos);
  const auto b = html.find("</script>", a);
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

struct Folder {
  PlotData data;
  io::CsvTable strains;
};
Folder read_folder(const fs::path& dir, StrainMeasure m = StrainMeasure::kTrue) {
  ResultsFolder f = read_results_folder(dir.string());
  io::CsvTable strains = f.strains;
  return {plot_data(std::move(f), m), std::move(strains)};
}

TEST(GsaView3d, MarksSitWhereTheyWereMeasured) {
  if (!view3d_available()) GTEST_SKIP() << view3d_library();
  const fs::path dir = test_dir("dome");
  const GridData grid = analyse_case("dome", dir);
  const Folder f = read_folder(dir);
  const View3d v = make_view3d(f.data, &f.strains);
  const nlohmann::json j = data_of(v.html);
  const auto& m = j["marks"];
  ASSERT_EQ(m["n"].get<Index>(), grid.n_points());
  EXPECT_EQ(v.stats.marks_unplaced, 0);
  const std::vector<float> pu = floats(m["pos_u"]), pd = floats(m["pos_d"]);
  std::map<std::string, Index> row;
  for (Index p = 0; p < grid.n_points(); ++p) row[grid.ids[p]] = p;
  double worst_u = 0, worst_d = 0;
  for (std::size_t k = 0; k < m["ids"].size(); ++k) {
    const Index p = row.at(m["ids"][k].get<std::string>());
    for (int c = 0; c < 3; ++c) {
      worst_u = std::max(worst_u, std::abs(pu[3 * k + c] - grid.undeformed(p, c)));
      worst_d = std::max(worst_d, std::abs(pd[3 * k + c] - grid.deformed(p, c)));
    }
  }
  // Bilinear inside an 8 x 8 tessellation cell of a sphere of 80 mm: sagitta ~ 1e-3 mm.
  EXPECT_LT(worst_u, 1e-3);
  EXPECT_LT(worst_d, 0.02) << "marks off the formed part by " << worst_d << " mm";
  std::cout << "dome, 81 marks: placed within " << worst_u << " mm (blank), " << worst_d << " mm (part)\n";
}

TEST(GsaView3d, SurfaceFieldsAreTheFittedStrain) {
  if (!view3d_available()) GTEST_SKIP() << view3d_library();
  const fs::path dir = test_dir("stretch");
  analyse_case("stretch", dir);
  const Folder f = read_folder(dir, StrainMeasure::kEngineering);
  const View3d v = make_view3d(f.data, &f.strains);
  const nlohmann::json j = data_of(v.html);
  const auto& fields = j["surface"]["fields"];
  ASSERT_GE(fields.size(), 7u);
  EXPECT_EQ(fields[0]["key"], "eng1");  // the measure's major first
  EXPECT_EQ(fields[1]["key"], "eng2");
  EXPECT_EQ(fields[2]["key"], "thickness_change_pct");
  EXPECT_EQ(fields[2]["unit"], "%");
  // Homogeneous stretch: every vertex carries the same strain as the marks.
  const double e1 = f.data.marks.major[0];
  const std::vector<float> vals = floats(fields[0]["data"]);
  ASSERT_EQ(vals.size(), j["surface"]["n_vertices"].get<std::size_t>());
  for (float x : vals) ASSERT_NEAR(x, e1, 1e-5);
  EXPECT_EQ(j["surface"]["quads_per_element_side"], 8);
  EXPECT_EQ(v.stats.triangles * 3, static_cast<Index>(floats(j["surface"]["index"]).size()));
  EXPECT_GT(v.stats.glyph_sites, 0);
}

TEST(GsaView3d, DecimatesUnderTheVertexBudget) {
  if (!view3d_available()) GTEST_SKIP() << view3d_library();
  const fs::path dir = test_dir("decimate");
  analyse_case("dome", dir);
  const Folder f = read_folder(dir);
  const View3dStats full = make_view3d(f.data, &f.strains).stats;
  View3dOptions o;
  o.max_vertices = full.vertices - 1;
  const View3dStats half = make_view3d(f.data, &f.strains, o).stats;
  EXPECT_EQ(full.quads_per_element_side, 8);
  EXPECT_EQ(half.quads_per_element_side, 4);
  EXPECT_LE(half.vertices, o.max_vertices);
  EXPECT_EQ(half.triangles * 4, full.triangles);  // all cells measured on this square grid
  o.max_vertices = 100;
  const View3dStats coarse = make_view3d(f.data, &f.strains, o).stats;
  EXPECT_LE(coarse.quads_per_element_side, 2);
  EXPECT_LE(coarse.vertices, 100);
  o.max_vertices = 0;
  EXPECT_THROW(make_view3d(f.data, &f.strains, o), UsageError);
}

TEST(GsaView3d, EveryColumnOfStrainsCsvIsOffered) {
  if (!view3d_available()) GTEST_SKIP() << view3d_library();
  const fs::path dir = test_dir("columns");
  analyse_case("dome", dir);
  Folder f = read_folder(dir);
  // Columns another tool adds (a thickness, a zone by name) show up without a change here.
  std::ifstream in(dir / "strains.csv");
  std::string text, line;
  int row = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#')
      line += row++ == 0 ? ",thickness_mm,zone,uniform_pct,near_strain"
              : row % 2  ? ",0.9,safe,5,0.2031"
                         : ",0.8,marginal,5,0.2029";
    text += line + "\n";
  }
  const io::CsvTable extended = io::read_csv_string(text, "strains.csv");
  const View3d v = make_view3d(f.data, &extended);
  const auto& cols = v.stats.mark_columns;
  for (const char* c : {"true1", "true2", "thickness_change_pct", "status", "thickness_mm", "zone"})
    EXPECT_NE(std::find(cols.begin(), cols.end(), c), cols.end()) << c;
  const nlohmann::json j = data_of(v.html);
  for (const auto& c : j["marks"]["columns"]) {
    if (c["key"] == "zone") {
      EXPECT_EQ(c["categories"], nlohmann::json({"marginal", "safe"}));
    }
    if (c["key"] == "thickness_mm") {
      EXPECT_EQ(c["unit"], "mm");
      EXPECT_NEAR(c["range"][0].get<double>(), 0.8, 1e-6);
    }
    // A (nearly) uniform field is coloured over the smallest range worth colouring, as in
    // the PNG plots (1 %, 0.01 of strain), not over its noise; its own span is kept beside.
    if (c["key"] == "uniform_pct") {
      EXPECT_NEAR(c["range"][0].get<double>(), 4.5, 1e-6);
      EXPECT_NEAR(c["range"][1].get<double>(), 5.5, 1e-6);
      EXPECT_NEAR(c["data_range"][0].get<double>(), 5.0, 1e-6);
      EXPECT_NEAR(c["data_range"][1].get<double>(), 5.0, 1e-6);
    }
    if (c["key"] == "near_strain") {
      // A column of unknown name has no unit: no widening.
      EXPECT_NEAR(c["range"][1].get<double>() - c["range"][0].get<double>(), 0.0002, 1e-6);
    }
  }
  for (const auto& sf : j["surface"]["fields"]) {
    const double span = sf["range"][1].get<double>() - sf["range"][0].get<double>();
    if (sf["unit"] == "-") {
      EXPECT_GE(span, 0.01 - 1e-12) << sf["key"];
    }
    if (sf["unit"] == "%") {
      EXPECT_GE(span, 1.0 - 1e-12) << sf["key"];
    }
  }
  // A small budget leaves out the directions first, and says so.
  View3dOptions o;
  o.max_mark_values = 81 * 13;
  const View3dStats st = make_view3d(f.data, &extended, o).stats;
  ASSERT_FALSE(st.mark_columns_left_out.empty());
  EXPECT_EQ(st.mark_columns_left_out.front(), "dir1u_x");
  EXPECT_LE(st.mark_columns.size() * 81, o.max_mark_values);
  EXPECT_NE(std::find(st.mark_columns.begin(), st.mark_columns.end(), "true1"), st.mark_columns.end());
}

TEST(GsaView3d, OneSelfContainedPage) {
  if (!view3d_available()) GTEST_SKIP() << view3d_library();
  const fs::path dir = test_dir("page");
  analyse_case("dome", dir);
  Folder f = read_folder(dir);
  f.data.case_name = "odd</script><b>name";
  View3dOptions o;
  o.full_window = true;
  const View3d v = make_view3d(f.data, &f.strains, o);
  EXPECT_EQ(v.html.find("<script src"), std::string::npos);
  EXPECT_EQ(v.html.find("<link"), std::string::npos);
  EXPECT_NE(v.html.find("THREE.OrbitControls"), std::string::npos);
  // The name cannot close a script early: 4 scripts (data, three.js, controls, the view).
  std::size_t n = 0;
  for (std::size_t p = 0; (p = v.html.find("</script>", p)) != std::string::npos; ++p) ++n;
  EXPECT_EQ(n, 4u);
  EXPECT_EQ(data_of(v.html)["title"], "odd</script><b>name");
  const View3dStats st = write_view_page(dir.string(), StrainMeasure::kTrue);
  EXPECT_TRUE(fs::exists(dir / "view.html"));
  EXPECT_EQ(st.marks, 81);
}

TEST(GsaView3d, TriangleMethodHasNoSurfaces) {
  const fs::path dir = test_dir("triangles");
  analyse_case("dome", dir, Method::kTriangles);
  try {
    write_view_page(dir.string(), StrainMeasure::kTrue);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(view3d_available() ? "needs the surface method" : "libjs-three"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "view.html"));
}

}  // namespace
}  // namespace sf::gsa
