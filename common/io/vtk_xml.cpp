#include "common/io/vtk_xml.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkExecutive.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <system_error>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/xml_escape.hpp"

namespace sf::io {

namespace fs = std::filesystem;

int n_cell_nodes(CellType type) {
  switch (type) {
    case CellType::kVertex:
      return 1;
    case CellType::kLine:
      return 2;
    case CellType::kTriangle:
      return 3;
    case CellType::kPolygon:
      return 0;
    case CellType::kQuad:
      return 4;
    case CellType::kTetra:
      return 4;
    case CellType::kHexahedron:
      return 8;
    case CellType::kWedge:
      return 6;
  }
  return -1;
}

namespace {

// Checks a cell's node count against its type; "" when fine, else what is wrong.
std::string check_node_count(CellType type, std::size_t n_nodes) {
  const int expected = n_cell_nodes(type);
  if (expected < 0) return fmt::format("unsupported VTK cell type {}", static_cast<int>(type));
  if (expected == 0) {
    return n_nodes >= 3 ? std::string() : fmt::format("a polygon needs >= 3 nodes, has {}", n_nodes);
  }
  if (n_nodes != static_cast<std::size_t>(expected)) {
    return fmt::format("VTK cell type {} needs {} nodes, has {}", static_cast<int>(type), expected, n_nodes);
  }
  return {};
}

}  // namespace

void VolumeMesh::add_cell(CellType type, const std::vector<Index>& nodes) {
  if (const std::string why = check_node_count(type, nodes.size()); !why.empty()) {
    throw std::logic_error("VolumeMesh::add_cell: " + why);
  }
  cell_types.push_back(type);
  connectivity.insert(connectivity.end(), nodes.begin(), nodes.end());
  offsets.push_back(static_cast<Index>(connectivity.size()));
}

namespace {

// ---------------------------------------------------------------------------------------
// VTK error capture: VTK reports errors through ErrorEvent when an observer listens (and
// prints them otherwise). We collect them so they end up in one exception message.

class VtkErrorCatcher {
 public:
  VtkErrorCatcher() {
    command_->SetCallback(&VtkErrorCatcher::on_event);
    command_->SetClientData(this);
  }
  void watch(vtkObject* object) {
    object->AddObserver(vtkCommand::ErrorEvent, command_);
    object->AddObserver(vtkCommand::WarningEvent, command_);
  }
  vtkCommand* command() { return command_; }
  bool failed() const { return failed_; }
  const std::string& message() const { return message_; }

 private:
  static void on_event(vtkObject* /*caller*/, unsigned long event, void* client, void* data) {
    auto* self = static_cast<VtkErrorCatcher*>(client);
    if (event == vtkCommand::ErrorEvent) self->failed_ = true;
    if (event != vtkCommand::ErrorEvent || !data || !self->message_.empty()) return;
    // "ERROR: In FILE, line N\nvtkClass (0x...): message\n\n" -> "message"
    std::string text(static_cast<const char*>(data));
    if (const auto nl = text.find('\n'); nl != std::string::npos && text.rfind("ERROR", 0) == 0) {
      text = text.substr(nl + 1);
    }
    if (const auto colon = text.find("): "); colon != std::string::npos) {
      text = text.substr(colon + 3);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    std::replace(text.begin(), text.end(), '\n', ' ');
    self->message_ = text;
  }

  vtkNew<vtkCallbackCommand> command_;
  bool failed_ = false;
  std::string message_;
};

// ---------------------------------------------------------------------------------------
// Conversions to VTK

void check_fields(const std::vector<FieldArray>& fields, std::size_t n_tuples, const char* where) {
  std::set<std::string> names;
  for (const FieldArray& f : fields) {
    if (f.name.empty()) throw std::logic_error(fmt::format("VTK {}: a field has no name", where));
    if (!names.insert(f.name).second) {
      throw std::logic_error(fmt::format("VTK {}: field '{}' appears twice", where, f.name));
    }
    if (f.n_components < 1) {
      throw std::logic_error(fmt::format("VTK {}: field '{}' has {} components", where, f.name, f.n_components));
    }
    const std::size_t expected = n_tuples * static_cast<std::size_t>(f.n_components);
    if (f.values.size() != expected) {
      throw std::logic_error(fmt::format("VTK {}: field '{}' has {} values, expected {} ({} tuples x {} components)",
                                         where, f.name, f.values.size(), expected, n_tuples, f.n_components));
    }
  }
}

void check_index(Index i, Index n_points, const char* what, std::size_t cell) {
  if (i < 0 || i >= n_points) {
    throw std::logic_error(
        fmt::format("VTK mesh: {} {} refers to point {}, but there are {}", what, cell, i, n_points));
  }
}

vtkSmartPointer<vtkPoints> make_points(const Points3& p) {
  vtkNew<vtkDoubleArray> coords;
  coords->SetNumberOfComponents(3);
  coords->SetNumberOfTuples(p.rows());
  if (p.size() > 0) {
    std::memcpy(coords->GetPointer(0), p.data(), sizeof(double) * static_cast<std::size_t>(p.size()));
  }
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetData(coords);
  return points;
}

void add_fields(vtkDataSetAttributes* attributes, const std::vector<FieldArray>& fields) {
  for (const FieldArray& f : fields) {
    vtkNew<vtkDoubleArray> array;
    array->SetName(f.name.c_str());
    array->SetNumberOfComponents(f.n_components);
    array->SetNumberOfTuples(static_cast<vtkIdType>(f.n_tuples()));
    if (!f.values.empty()) {
      std::memcpy(array->GetPointer(0), f.values.data(), sizeof(double) * f.values.size());
    }
    attributes->AddArray(array);
  }
}

vtkSmartPointer<vtkCellArray> make_cells(const std::vector<std::vector<Index>>& cells, Index n_points,
                                         std::size_t min_nodes, const char* what) {
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfTuples(static_cast<vtkIdType>(cells.size() + 1));
  vtkIdType total = 0;
  offsets->SetValue(0, 0);
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (cells[c].size() < min_nodes) {
      throw std::logic_error(
          fmt::format("VTK mesh: {} {} has {} points, needs >= {}", what, c, cells[c].size(), min_nodes));
    }
    total += static_cast<vtkIdType>(cells[c].size());
    offsets->SetValue(static_cast<vtkIdType>(c + 1), total);
  }
  connectivity->SetNumberOfTuples(total);
  vtkIdType k = 0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    for (const Index i : cells[c]) {
      check_index(i, n_points, what, c);
      connectivity->SetValue(k++, static_cast<vtkIdType>(i));
    }
  }
  auto array = vtkSmartPointer<vtkCellArray>::New();
  array->SetData(offsets, connectivity);
  return array;
}

void configure(vtkXMLWriter* writer, const VtkWriteOptions& options) {
  writer->SetHeaderTypeToUInt64();
  if (options.ascii) {
    writer->SetDataModeToAscii();
  } else {
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();  // raw binary
  }
  if (options.compress && !options.ascii) {
    writer->SetCompressorTypeToLZ4();
  } else {
    writer->SetCompressorTypeToNone();
  }
}

// Runs `writer` into a temporary sibling of `path`, then renames it into place.
void run_writer(vtkXMLWriter* writer, const std::string& path) {
  const std::string tmp = path + fmt::format(".tmp-{}", static_cast<long>(::getpid()));
  VtkErrorCatcher errors;
  errors.watch(writer);
  errors.watch(writer->GetExecutive());  // "returned failure for request" comes from here
  writer->SetFileName(tmp.c_str());
  const int ok = writer->Write();
  std::error_code ec;
  if (ok != 1 || errors.failed()) {
    fs::remove(tmp, ec);
    std::string why = errors.message().empty() ? "VTK writer failed" : errors.message();
    if (const auto at = why.find(tmp); at != std::string::npos) why.replace(at, tmp.size(), path);
    throw Error(located_message(path, 0, 0, "cannot write VTK file (" + why + ")"));
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw Error(located_message(path, 0, 0, "cannot write VTK file (" + ec.message() + ")"));
  }
}

// ---------------------------------------------------------------------------------------
// Conversions from VTK

void check_readable(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw InputError(located_message(path, 0, 0,
                                     fs::exists(path, ec) ? "cannot open file (not a regular file)"
                                                          : "cannot open file (No such file or directory)"));
  }
}

template <class Reader>
void run_reader(Reader* reader, const std::string& path) {
  check_readable(path);
  VtkErrorCatcher errors;
  errors.watch(reader);
  errors.watch(reader->GetExecutive());
  reader->SetReaderErrorObserver(errors.command());
  reader->SetParserErrorObserver(errors.command());
  reader->SetFileName(path.c_str());
  reader->Update();
  if (errors.failed() || reader->GetOutput() == nullptr) {
    const std::string why = errors.message().empty() ? "VTK reader failed" : errors.message();
    throw InputError(located_message(path, 0, 0, "cannot read VTK file (" + why + ")"));
  }
}

Points3 read_points(vtkPoints* points) {
  const Index n = points ? static_cast<Index>(points->GetNumberOfPoints()) : 0;
  Points3 out(n, 3);
  for (Index i = 0; i < n; ++i) {
    double x[3];
    points->GetPoint(static_cast<vtkIdType>(i), x);
    out.row(i) << x[0], x[1], x[2];
  }
  return out;
}

std::vector<FieldArray> read_fields(vtkDataSetAttributes* attributes) {
  std::vector<FieldArray> out;
  if (!attributes) return out;
  for (int a = 0; a < attributes->GetNumberOfArrays(); ++a) {
    vtkDataArray* array = attributes->GetArray(a);  // null for non-numeric arrays
    if (!array) continue;
    FieldArray f;
    f.name = array->GetName() ? array->GetName() : "";
    f.n_components = array->GetNumberOfComponents();
    const vtkIdType n = array->GetNumberOfTuples();
    f.values.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(f.n_components));
    for (vtkIdType t = 0; t < n; ++t) {
      array->GetTuple(t, f.values.data() + static_cast<std::size_t>(t) * f.n_components);
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<std::vector<Index>> read_cells(vtkCellArray* cells) {
  std::vector<std::vector<Index>> out;
  if (!cells) return out;
  out.reserve(static_cast<std::size_t>(cells->GetNumberOfCells()));
  auto it = vtk::TakeSmartPointer(cells->NewIterator());
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell()) {
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    it->GetCurrentCell(n, ids);
    out.emplace_back(ids, ids + n);
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------

void write_vtp(const std::string& path, const PolyMesh& mesh, const VtkWriteOptions& options) {
  const Index n_points = mesh.n_points();
  check_fields(mesh.point_data, static_cast<std::size_t>(n_points), "point data");
  check_fields(mesh.cell_data, mesh.n_cells(), "cell data");

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(make_points(mesh.points));
  if (!mesh.vertices.empty()) {
    std::vector<std::vector<Index>> verts;
    verts.reserve(mesh.vertices.size());
    for (const Index i : mesh.vertices) verts.push_back({i});
    poly->SetVerts(make_cells(verts, n_points, 1, "vertex"));
  }
  if (!mesh.lines.empty()) poly->SetLines(make_cells(mesh.lines, n_points, 2, "line"));
  if (!mesh.polygons.empty()) {
    poly->SetPolys(make_cells(mesh.polygons, n_points, 3, "polygon"));
  }
  add_fields(poly->GetPointData(), mesh.point_data);
  add_fields(poly->GetCellData(), mesh.cell_data);

  vtkNew<vtkXMLPolyDataWriter> writer;
  configure(writer, options);
  writer->SetInputData(poly);
  run_writer(writer, path);
}

void write_vtu(const std::string& path, const VolumeMesh& mesh, const VtkWriteOptions& options) {
  const Index n_points = mesh.n_points();
  const std::size_t n_cells = mesh.n_cells();
  if (mesh.offsets.size() != n_cells + 1 || mesh.offsets.front() != 0 ||
      mesh.offsets.back() != static_cast<Index>(mesh.connectivity.size())) {
    throw std::logic_error(
        fmt::format("VTK volume mesh: {} cell types, {} offsets (expected n_cells + 1, from 0 to {})", n_cells,
                    mesh.offsets.size(), mesh.connectivity.size()));
  }
  check_fields(mesh.point_data, static_cast<std::size_t>(n_points), "point data");
  check_fields(mesh.cell_data, n_cells, "cell data");

  vtkNew<vtkUnsignedCharArray> types;
  types->SetNumberOfTuples(static_cast<vtkIdType>(n_cells));
  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfTuples(static_cast<vtkIdType>(n_cells + 1));
  offsets->SetValue(0, 0);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const Index begin = mesh.offsets[c];
    const Index end = mesh.offsets[c + 1];
    if (end < begin) throw std::logic_error(fmt::format("VTK volume mesh: offsets decrease at cell {}", c));
    const std::string why = check_node_count(mesh.cell_types[c], static_cast<std::size_t>(end - begin));
    if (!why.empty()) throw std::logic_error(fmt::format("VTK volume mesh: cell {}: {}", c, why));
    types->SetValue(static_cast<vtkIdType>(c), static_cast<unsigned char>(mesh.cell_types[c]));
    offsets->SetValue(static_cast<vtkIdType>(c + 1), static_cast<vtkIdType>(end));
  }
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfTuples(static_cast<vtkIdType>(mesh.connectivity.size()));
  for (std::size_t c = 0; c < n_cells; ++c) {
    for (Index k = mesh.offsets[c]; k < mesh.offsets[c + 1]; ++k) {
      const Index i = mesh.connectivity[static_cast<std::size_t>(k)];
      check_index(i, n_points, "cell", c);
      connectivity->SetValue(static_cast<vtkIdType>(k), static_cast<vtkIdType>(i));
    }
  }
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);

  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(make_points(mesh.points));
  grid->SetCells(types, cells);
  add_fields(grid->GetPointData(), mesh.point_data);
  add_fields(grid->GetCellData(), mesh.cell_data);

  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  configure(writer, options);
  writer->SetInputData(grid);
  run_writer(writer, path);
}

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& time_and_relative_file) {
  std::vector<PvdDataSet> sets;
  for (const auto& [time, file] : time_and_relative_file) sets.push_back({time, file, 0});
  write_pvd(path, sets);
}

void write_pvd(const std::string& path, const std::vector<PvdDataSet>& data_sets) {
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const PvdDataSet& d : data_sets) {
    if (!std::isfinite(d.time)) {
      throw std::logic_error(fmt::format("write_pvd: time {} of '{}' is not finite", d.time, d.file));
    }
    xml += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", d.time, d.part,
                       xml_escape(d.file));
  }
  xml +=
      "  </Collection>\n"
      "</VTKFile>\n";
  write_file_atomic(path, xml);
}

PolyMesh read_vtp(const std::string& path) {
  vtkNew<vtkXMLPolyDataReader> reader;
  run_reader(reader.GetPointer(), path);
  vtkPolyData* poly = reader->GetOutput();
  if (poly->GetNumberOfStrips() > 0) {
    throw InputError(located_message(path, 0, 0, "triangle strips are not supported"));
  }
  PolyMesh mesh;
  mesh.points = read_points(poly->GetPoints());
  for (const auto& v : read_cells(poly->GetVerts())) {
    mesh.vertices.insert(mesh.vertices.end(), v.begin(), v.end());
  }
  mesh.lines = read_cells(poly->GetLines());
  mesh.polygons = read_cells(poly->GetPolys());
  mesh.point_data = read_fields(poly->GetPointData());
  mesh.cell_data = read_fields(poly->GetCellData());
  if (mesh.vertices.size() != static_cast<std::size_t>(poly->GetNumberOfVerts())) {
    throw InputError(located_message(path, 0, 0, "poly-vertex cells (several points) are not supported"));
  }
  return mesh;
}

VolumeMesh read_vtu(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  run_reader(reader.GetPointer(), path);
  vtkUnstructuredGrid* grid = reader->GetOutput();
  VolumeMesh mesh;
  mesh.points = read_points(grid->GetPoints());
  const vtkIdType n_cells = grid->GetNumberOfCells();
  if (n_cells > 0) {
    vtkUnsignedCharArray* types = grid->GetCellTypesArray();
    const auto cells = read_cells(grid->GetCells());
    for (vtkIdType c = 0; c < n_cells; ++c) {
      mesh.cell_types.push_back(static_cast<CellType>(types->GetValue(c)));
      const auto& nodes = cells[static_cast<std::size_t>(c)];
      mesh.connectivity.insert(mesh.connectivity.end(), nodes.begin(), nodes.end());
      mesh.offsets.push_back(static_cast<Index>(mesh.connectivity.size()));
    }
  }
  mesh.point_data = read_fields(grid->GetPointData());
  mesh.cell_data = read_fields(grid->GetCellData());
  return mesh;
}

}  // namespace sf::io
