#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "common/core/error.hpp"
#include "common/io/vtk_xml.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

using ::testing::HasSubstr;

// Two triangles and a quad on a 3 x 2 grid of points, a polyline along the bottom, a vertex.
PolyMesh make_surface() {
  PolyMesh mesh;
  mesh.points.resize(6, 3);
  mesh.points << 0, 0, 0,  //
      1, 0, 0.1,           //
      2, 0, 0.2,           //
      0, 1, 0,             //
      1, 1, 0.1,           //
      2, 1, 1.0 / 3.0;
  mesh.vertices = {5};
  mesh.lines = {{0, 1, 2}};
  mesh.polygons = {{0, 1, 4, 3}, {1, 2, 5}, {1, 5, 4}};
  FieldArray e1{"E1", 1, {0.1, 0.2, 0.3, 0.4, 0.5, 1e-17}};
  FieldArray dir{"dir1", 3, {}};
  for (int i = 0; i < 6; ++i) dir.values.insert(dir.values.end(), {1.0 * i, -0.5, 0.25});
  mesh.point_data = {e1, dir};
  mesh.cell_data = {FieldArray{"element", 1, {-1, -2, 0, 1, 2}}};  // vertex, line, 3 polygons
  return mesh;
}

void expect_same_surface(const PolyMesh& a, const PolyMesh& b) {
  ASSERT_EQ(a.points.rows(), b.points.rows());
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.lines, b.lines);
  EXPECT_EQ(a.polygons, b.polygons);
  ASSERT_EQ(a.point_data.size(), b.point_data.size());
  for (std::size_t f = 0; f < a.point_data.size(); ++f) {
    EXPECT_EQ(a.point_data[f].name, b.point_data[f].name);
    EXPECT_EQ(a.point_data[f].n_components, b.point_data[f].n_components);
    EXPECT_EQ(a.point_data[f].values, b.point_data[f].values) << a.point_data[f].name;
  }
  ASSERT_EQ(a.cell_data.size(), b.cell_data.size());
  for (std::size_t f = 0; f < a.cell_data.size(); ++f) {
    EXPECT_EQ(a.cell_data[f].name, b.cell_data[f].name);
    EXPECT_EQ(a.cell_data[f].values, b.cell_data[f].values);
  }
}

TEST(IoVtkXml, VtpRoundTripBinaryCompressed) {
  test::ScratchDir dir;
  const PolyMesh mesh = make_surface();
  write_vtp(dir.file("s.vtp"), mesh);
  const std::string text = test::read_text(dir.path() / "s.vtp");
  EXPECT_THAT(text, HasSubstr("type=\"PolyData\""));
  EXPECT_THAT(text, HasSubstr("vtkLZ4DataCompressor"));
  expect_same_surface(mesh, read_vtp(dir.file("s.vtp")));
}

TEST(IoVtkXml, VtpRoundTripAscii) {
  test::ScratchDir dir;
  const PolyMesh mesh = make_surface();
  VtkWriteOptions options;
  options.ascii = true;
  write_vtp(dir.file("s.vtp"), mesh, options);
  EXPECT_THAT(test::read_text(dir.path() / "s.vtp"), HasSubstr("format=\"ascii\""));
  expect_same_surface(mesh, read_vtp(dir.file("s.vtp")));
}

TEST(IoVtkXml, VtuHexahedronAndWedgeReadBack) {
  test::ScratchDir dir;
  VolumeMesh mesh;
  mesh.points.resize(10, 3);
  mesh.points << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1,             //
      2, 0, 0, 2, 0, 1;
  mesh.add_cell(CellType::kHexahedron, {0, 1, 2, 3, 4, 5, 6, 7});
  mesh.add_cell(CellType::kWedge, {1, 8, 2, 5, 9, 6});
  mesh.add_cell(CellType::kQuad, {0, 1, 5, 4});
  std::vector<double> u;
  for (int i = 0; i < 10; ++i) u.insert(u.end(), {0.01 * i, 0.0, -0.02 * i});
  mesh.point_data = {FieldArray{"displacement", 3, u}};
  mesh.cell_data = {FieldArray{"ply", 1, {1, 2, 3}}};
  write_vtu(dir.file("step.vtu"), mesh);

  const VolumeMesh back = read_vtu(dir.file("step.vtu"));
  EXPECT_EQ(back.points, mesh.points);
  ASSERT_EQ(back.n_cells(), 3u);
  EXPECT_EQ(back.cell_types, mesh.cell_types);
  EXPECT_EQ(back.offsets, mesh.offsets);
  EXPECT_EQ(back.connectivity, mesh.connectivity);
  ASSERT_EQ(back.point_data.size(), 1u);
  EXPECT_EQ(back.point_data[0].name, "displacement");
  EXPECT_EQ(back.point_data[0].n_components, 3);
  EXPECT_EQ(back.point_data[0].values, u);
  ASSERT_EQ(back.cell_data.size(), 1u);
  EXPECT_EQ(back.cell_data[0].values, (std::vector<double>{1, 2, 3}));
}

TEST(IoVtkXml, SizeMistakesAreLogicErrorsNamingTheField) {
  test::ScratchDir dir;
  PolyMesh mesh = make_surface();
  mesh.point_data[1].values.pop_back();
  EXPECT_THAT(test::message_of<std::logic_error>([&] { write_vtp(dir.file("a.vtp"), mesh); }), HasSubstr("'dir1'"));
  mesh = make_surface();
  mesh.cell_data[0].values.pop_back();  // forgot the vertex or the line
  EXPECT_THAT(test::message_of<std::logic_error>([&] { write_vtp(dir.file("a.vtp"), mesh); }), HasSubstr("'element'"));
  mesh = make_surface();
  mesh.polygons[1][2] = 6;
  EXPECT_THAT(test::message_of<std::logic_error>([&] { write_vtp(dir.file("a.vtp"), mesh); }),
              HasSubstr("polygon 1 refers to point 6"));
  VolumeMesh volume;
  EXPECT_THROW(volume.add_cell(CellType::kHexahedron, {0, 1, 2}), std::logic_error);
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.vtp")));
}

TEST(IoVtkXml, WriterAndReaderFailuresNameThePath) {
  test::ScratchDir dir;
  const std::string bad = dir.file("no/such/dir/s.vtp");
  EXPECT_THAT(test::message_of<Error>([&] { write_vtp(bad, make_surface()); }),
              HasSubstr(bad + ": cannot write VTK file"));
  EXPECT_THAT(test::message_of<InputError>([&] { read_vtp(dir.file("none.vtp")); }),
              HasSubstr(dir.file("none.vtp") + ": cannot open file"));
  test::write_text(dir.path() / "junk.vtp", "this is not XML");
  EXPECT_THAT(test::message_of<InputError>([&] { read_vtp(dir.file("junk.vtp")); }),
              HasSubstr(dir.file("junk.vtp") + ": cannot read VTK file"));
}

TEST(IoVtkXml, PvdListsStepsInOrder) {
  test::ScratchDir dir;
  write_pvd(dir.file("run.pvd"),
            std::vector<std::pair<double, std::string>>{{0.0, "steps/step_0000.vtu"}, {0.125, "steps/a&b.vtu"}});
  EXPECT_EQ(test::read_text(dir.path() / "run.pvd"),
            "<?xml version=\"1.0\"?>\n"
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
            "  <Collection>\n"
            "    <DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"steps/step_0000.vtu\"/>\n"
            "    <DataSet timestep=\"0.125\" group=\"\" part=\"0\" file=\"steps/a&amp;b.vtu\"/>\n"
            "  </Collection>\n"
            "</VTKFile>\n");
  EXPECT_THROW(write_pvd(dir.file("x.pvd"), std::vector<std::pair<double, std::string>>{{std::nan(""), "a.vtu"}}),
               std::logic_error);
}

}  // namespace
}  // namespace sf::io
