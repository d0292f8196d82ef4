#pragma once
// VTK XML files for ParaView: surfaces (.vtp), volume meshes (.vtu) and time series (.pvd).
// Plain data structs here; the VTK library is used only inside vtk_xml.cpp.
//
// Field arrays hold one tuple per point (point_data) or per cell (cell_data), tuple-major:
//   values = [t0c0, t0c1, t0c2, t1c0, ...]   (n_tuples * n_components)
// A 3-component array shows in ParaView as a vector (glyphs, "Magnitude").

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"

namespace sf::io {

struct FieldArray {
  std::string name;            // unique within its point_data / cell_data, not empty
  int n_components = 1;        // >= 1
  std::vector<double> values;  // n_tuples * n_components, tuple-major

  std::size_t n_tuples() const { return n_components > 0 ? values.size() / static_cast<std::size_t>(n_components) : 0; }
};

// A surface: points with vertex, line and polygon cells (0-based point indices).
// VTK numbers cells in the order vertices, then lines, then polygons: cell_data arrays have
// n_cells() = vertices.size() + lines.size() + polygons.size() tuples in that order.
struct PolyMesh {
  Points3 points;                            // n_points x 3 (model units, e.g. mm)
  std::vector<Index> vertices;               // one point per vertex cell
  std::vector<std::vector<Index>> lines;     // polylines, >= 2 points each
  std::vector<std::vector<Index>> polygons;  // >= 3 points each, counter-clockwise seen from
                                             // the side the normal points to
  std::vector<FieldArray> point_data;        // n_points tuples each
  std::vector<FieldArray> cell_data;         // n_cells() tuples each

  Index n_points() const { return points.rows(); }
  std::size_t n_cells() const { return vertices.size() + lines.size() + polygons.size(); }
};

// VTK cell type codes (vtkCellType.h) with their node counts; node orderings are VTK's
// (hexahedron: bottom face 0-1-2-3 counter-clockwise seen from above, top face 4-5-6-7 above
// them; wedge: triangle 0-1-2 and triangle 3-4-5 above it).
enum class CellType : std::uint8_t {
  kVertex = 1,       // 1 node
  kLine = 3,         // 2
  kTriangle = 5,     // 3
  kPolygon = 7,      // any >= 3
  kQuad = 9,         // 4
  kTetra = 10,       // 4
  kHexahedron = 12,  // 8
  kWedge = 13,       // 6
};

// Node count of a cell type (0 for kPolygon: any count >= 3).
int n_cell_nodes(CellType type);

// A volume (or mixed) mesh in VTK's flat layout. Build it with add_cell().
struct VolumeMesh {
  Points3 points;                      // n_points x 3
  std::vector<CellType> cell_types;    // n_cells
  std::vector<Index> offsets{0};       // n_cells + 1; cell c is connectivity[offsets[c],
                                       // offsets[c+1])
  std::vector<Index> connectivity;     // 0-based point indices
  std::vector<FieldArray> point_data;  // n_points tuples each
  std::vector<FieldArray> cell_data;   // n_cells tuples each

  Index n_points() const { return points.rows(); }
  std::size_t n_cells() const { return cell_types.size(); }
  void add_cell(CellType type, const std::vector<Index>& nodes);
};

struct VtkWriteOptions {
  bool ascii = false;    // human-readable text instead of appended binary
  bool compress = true;  // LZ4 compression of binary data (fast; ParaView and VTK >= 8 read it)
};

// Write a file atomically (temporary sibling + rename). Sizes and indices are checked: a
// field of the wrong length, an index out of range or a wrong node count is a programming
// error and throws std::logic_error naming the field or cell. A failing writer throws
// sf::Error naming the path.
void write_vtp(const std::string& path, const PolyMesh& mesh, const VtkWriteOptions& options = {});
void write_vtu(const std::string& path, const VolumeMesh& mesh, const VtkWriteOptions& options = {});

// A ParaView collection: (time, file relative to the .pvd) per step, in the order given.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& time_and_relative_file);
// The same with several data sets per time step: each its part number (ParaView shows
// the parts of one time together, e.g. the plies, the tools and the contact points).
struct PvdDataSet {
  double time = 0.0;
  std::string file;  // relative to the .pvd
  int part = 0;
};
void write_pvd(const std::string& path, const std::vector<PvdDataSet>& data_sets);

// Readers (for tests and for plotting results). Every data array is converted to double.
// Throws sf::InputError "PATH: cannot open file ..." or "PATH: cannot read VTK file (why)".
PolyMesh read_vtp(const std::string& path);
// Cells of types other than those in CellType are read with their VTK code unchanged.
VolumeMesh read_vtu(const std::string& path);

}  // namespace sf::io
