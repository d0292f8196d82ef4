#pragma once
// The interactive 3-D view of a results folder (issue 17 item 4; docs/usage.md "3-D view"):
// the fitted undeformed and deformed surfaces, the marks and the principal strain arrows,
// drawn in the browser with WebGL. report.html holds it at the top of its pictures
// (`gsa analyse`, `gsa plot`); `gsa view DIR` writes view.html, the view alone filling the
// window, without a display and without redrawing the pictures.
//
// One self-contained page that opens offline: three.js r111 (Debian's libjs-three, MIT
// licence) with its OrbitControls and the page's own script (gsa/view3d.js) are inlined,
// built into gsa at compile time (gsa/CMakeLists.txt). The data go in as one JSON object
// whose arrays are little-endian Float32 / Uint32 in base64.
//
// What is embedded:
//  - the surfaces as undeformed.vtp / deformed.vtp hold them: (subdiv)^2 quads per element
//    (8 x 8), only the cells where marks are (gsa/measured_region.hpp); each quad two
//    triangles. Above View3dOptions::max_vertices the tessellation is decimated to 4 x 4,
//    2 x 2 or 1 x 1 quads per element (a coarse cell is kept when all its fine cells are).
//    Fields: every one-component point field of the surfaces (major, minor in every
//    measure, thickness change, stretches; fibre mode: shear angle, fibre stretches).
//  - the principal strain arrows at element centres (2 x 2 sites per element up to 400
//    elements), with the directions of both surfaces and the strains in the page's measure.
//  - the marks of strains.csv, placed on both tessellated surfaces at (element, xi1, xi2)
//    (bilinear inside a tessellation cell): every numeric column of strains.csv (others:
//    columns with few distinct texts such as status are shown as categories), so columns
//    other tools add show up without a change here. Above max_mark_values (marks x
//    columns) the columns least looked at (directions, fitted positions, flag details) are
//    left out, and the page says which.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/csv.hpp"
#include "gsa/plots.hpp"

namespace sf::gsa {

struct View3dOptions {
  Index max_vertices = 60000;               // surface vertices in the page (before decimation: 81 per element)
  std::size_t max_mark_values = 1'000'000;  // marks x embedded numeric columns
  bool full_window = false;                 // view.html: the view fills the window
  // Throws OptionError naming the field for a value out of range.
  void validate() const;
};

struct View3dStats {
  Index vertices = 0, triangles = 0;  // embedded surface tessellation (per surface)
  int quads_per_element_side = 0;     // 8, or 4, 2, 1 after decimation
  Index glyph_sites = 0;
  Index marks = 0, marks_unplaced = 0;  // placed on the surfaces / without element and xi
  std::vector<std::string> surface_fields, mark_columns, mark_columns_left_out;
  std::size_t data_bytes = 0;  // the embedded JSON with its base64 arrays
};

struct View3d {
  std::string html;  // the <section> (report.html) or the whole page (full_window)
  View3dStats stats;
};

// True when gsa was built with three.js (libjs-three present at build time).
bool view3d_available();
// "three.js r111 (Debian libjs-three, MIT licence)", or why the view is missing.
std::string view3d_library();

// The view of `data` (needs has_surfaces) with the marks of `strains` (strains.csv of the
// same results; null: no marks). Throws sf::InputError when the surfaces lack a field the
// arrows need or strains.csv has no element / xi1 / xi2 columns, sf::Error when gsa was
// built without three.js.
View3d make_view3d(const PlotData& data, const io::CsvTable* strains, const View3dOptions& options = {});

// `gsa view DIR`: reads the results folder and writes the page to `out` (empty:
// DIR/view.html) through a temporary file: the page is complete or absent. Returns what
// was embedded.
View3dStats write_view_page(const std::string& dir, StrainMeasure measure, const View3dOptions& options = {},
                            const std::string& out = {});

}  // namespace sf::gsa
