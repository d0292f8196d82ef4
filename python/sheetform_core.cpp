// sheetform._core: the Python binding of `gsa analyse` (docs/python.md). The public face is
// python/sheetform/__init__.py; this file only converts between NumPy arrays and the
// library's structs, and turns the library's errors into Python exceptions with the
// command line's messages (options are named by their flags, e.g. "--smoothing-scale").
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <functional>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "gsa/analysis.hpp"
#include "gsa/analysis_checks.hpp"
#include "gsa/command_options.hpp"
#include "gsa/grid.hpp"
#include "gsa/mark_strains.hpp"
#include "gsa/output.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/surfaces_file.hpp"

namespace py = pybind11;

namespace {

using sf::Index;
using sf::InputError;
using sf::UsageError;
using sf::gsa::AnalyseFlags;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ------------------------------------------------------------------ options

std::string flag_name(const std::string& key) {
  std::string f = "--" + key;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::string as_text(const py::handle& v, const std::string& key) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  throw UsageError(flag_name(key) + ": expected text, found " + py::str(v).cast<std::string>());
}

double as_number(const py::handle& v, const std::string& key) {
  if (py::isinstance<py::bool_>(v) ||
      !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v) || py::hasattr(v, "__float__")))
    throw UsageError(flag_name(key) + ": expected a number, found " + py::repr(v).cast<std::string>());
  return v.cast<double>();
}

// "0,90" from [0, 90] (or the text as given); "7x5" from (7, 5).
std::string joined(const py::handle& v, const std::string& key, const char* sep) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (!py::isinstance<py::sequence>(v) && !py::hasattr(v, "__iter__"))
    throw UsageError(flag_name(key) + ": expected text or a sequence, found " + py::repr(v).cast<std::string>());
  std::ostringstream s;
  s.precision(17);
  bool first = true;
  for (const py::handle& x : v) {
    if (!first) s << sep;
    first = false;
    if (py::isinstance<py::int_>(x))
      s << x.cast<long long>();
    else
      s << as_number(x, key);
  }
  return s.str();
}

// The keyword options of analyse(): the flags of `gsa analyse` without the leading dashes,
// '-' written '_' (smoothing_scale=2 is --smoothing-scale 2).
AnalyseFlags flags_from(const py::dict& options) {
  AnalyseFlags f;
  using Setter = std::function<void(const py::handle&, const std::string&)>;
  auto text = [](std::string AnalyseFlags::*m, AnalyseFlags& flags) -> Setter {
    return [&flags, m](const py::handle& v, const std::string& k) { flags.*m = as_text(v, k); };
  };
  auto number = [](double AnalyseFlags::*m, AnalyseFlags& flags) -> Setter {
    return [&flags, m](const py::handle& v, const std::string& k) { flags.*m = as_number(v, k); };
  };
  auto optional_number = [](std::optional<double> AnalyseFlags::*m, AnalyseFlags& flags) -> Setter {
    return [&flags, m](const py::handle& v, const std::string& k) { flags.*m = as_number(v, k); };
  };
  auto integer = [](int AnalyseFlags::*m, AnalyseFlags& flags) -> Setter {
    return [&flags, m](const py::handle& v, const std::string& k) {
      const double x = as_number(v, k);
      if (x != std::floor(x))
        throw UsageError(flag_name(k) + ": expected a whole number, found " + py::repr(v).cast<std::string>());
      flags.*m = static_cast<int>(x);
    };
  };
  const std::map<std::string, Setter> setters = {
      {"method", text(&AnalyseFlags::method, f)},
      {"penalty", text(&AnalyseFlags::penalty, f)},
      {"smoothing_rule", text(&AnalyseFlags::smoothing_rule, f)},
      {"elements", [&f](const py::handle& v, const std::string& k) { f.elements = joined(v, k, "x"); }},
      {"mesh", text(&AnalyseFlags::mesh, f)},
      {"fibres", [&f](const py::handle& v, const std::string& k) { f.fibres = joined(v, k, ","); }},
      {"units", text(&AnalyseFlags::units, f)},
      {"format", text(&AnalyseFlags::format, f)},
      {"columns", text(&AnalyseFlags::columns, f)},
      {"id", text(&AnalyseFlags::id, f)},
      {"positions", text(&AnalyseFlags::positions, f)},
      {"delimiter", text(&AnalyseFlags::delimiter, f)},
      {"decimal", text(&AnalyseFlags::decimal, f)},
      {"skip_lines", integer(&AnalyseFlags::skip_lines, f)},
      {"header_line", integer(&AnalyseFlags::header_line, f)},
      {"pitch", number(&AnalyseFlags::pitch, f)},
      {"pixel_size", number(&AnalyseFlags::pixel_size, f)},
      {"alpha", optional_number(&AnalyseFlags::alpha, f)},
      {"beta", optional_number(&AnalyseFlags::beta, f)},
      {"gamma", optional_number(&AnalyseFlags::gamma, f)},
      {"delta", optional_number(&AnalyseFlags::delta, f)},
      {"outlier_sigma", number(&AnalyseFlags::outlier_sigma, f)},
      {"smoothing_scale", number(&AnalyseFlags::smoothing_scale, f)},
      {"no_local_smoothing", [&f](const py::handle& v, const std::string&) { f.no_local_smoothing = v.cast<bool>(); }},
  };
  for (const auto& [k, v] : options) {
    const std::string key = k.cast<std::string>();
    const auto it = setters.find(key);
    if (it == setters.end()) {
      std::string known;
      for (const auto& s : setters) known += (known.empty() ? "" : ", ") + s.first;
      throw UsageError("unknown option '" + key + "' (the options are those of gsa analyse, '-' written '_': " + known +
                       ")");
    }
    if (v.is_none()) continue;
    it->second(v, key);
  }
  f.no_plots = true;
  return f;
}

// ------------------------------------------------------------------ arrays

py::array_t<double> vector_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<double> rows3(const std::vector<sf::Vec3>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) m(static_cast<py::ssize_t>(i), c) = v[i][c];
  return a;
}

// An (n, 3) array of positions; NaN rows are "not digitised".
sf::Points3 points_from(const py::handle& obj, const char* name, Index expected_rows) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(1) != 3) {
    std::string found;
    if (a) {
      found = ", found shape (";
      for (py::ssize_t d = 0; d < a.ndim(); ++d) found += (d ? ", " : "") + std::to_string(a.shape(d));
      found += a.ndim() == 1 ? ",)" : ")";
    }
    throw InputError(std::string(name) + ": expected an array of shape (n, 3) (x, y, z per mark)" + found);
  }
  if (expected_rows >= 0 && a.shape(0) != expected_rows)
    throw InputError(std::string(name) + ": " + std::to_string(a.shape(0)) + " rows, but undeformed has " +
                     std::to_string(expected_rows) + " (one row per mark in both)");
  sf::Points3 p(a.shape(0), 3);
  std::copy(a.data(), a.data() + a.size(), p.data());
  return p;
}

// ------------------------------------------------------------------ results

struct Surface {
  std::shared_ptr<const sf::gsa::AnalysisResult> result;

  Index n_elements() const { return result->mesh.n_elements(); }

  // Values at (element, xi) for one point or many: X, x (positions on the undeformed and
  // deformed surfaces), the principal stretches and strains, major directions, fibres.
  py::dict evaluate(const py::handle& element_obj, const py::handle& xi_obj) const {
    const auto elements = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(element_obj);
    const auto xis = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(xi_obj);
    if (!elements || elements.ndim() > 1)
      throw InputError("element: expected an element number or a 1-D array of them");
    const bool single = elements.ndim() == 0;
    const py::ssize_t n = single ? 1 : elements.shape(0);
    if (!xis || !((xis.ndim() == 1 && xis.shape(0) == 2 && single) ||
                  (xis.ndim() == 2 && xis.shape(1) == 2 && xis.shape(0) == n)))
      throw InputError("xi: expected (xi1, xi2) for one element, or an array of shape (n, 2) for n elements");
    const sf::gsa::SurfacePair pair(result->mesh, result->undeformed_parameters, result->deformed_parameters);
    std::vector<sf::Vec3> X(n), x(n), d1(n), d2(n);
    std::vector<double> l1(n, kNaN), l2(n, kNaN), e1(n, kNaN), e2(n, kNaN), g1(n, kNaN), g2(n, kNaN), t1(n, kNaN),
        t2(n, kNaN), th(n, kNaN), shear(n, kNaN);
    const std::size_t nf = result->fibre_angles.size();
    std::vector<std::vector<sf::Vec3>> fdir(nf, std::vector<sf::Vec3>(n));
    std::vector<std::vector<double>> fstretch(nf, std::vector<double>(n, kNaN));
    const long long* ev = elements.data();
    const double* xv = xis.data();
    for (py::ssize_t i = 0; i < n; ++i) {
      const long long e = ev[i];
      const sf::Vec2 xi(xv[2 * i], xv[2 * i + 1]);
      if (e < 0 || e >= n_elements())
        throw InputError("element: " + std::to_string(e) + " is not an element of the mesh (0.." +
                         std::to_string(n_elements() - 1) + ")");
      if (!(xi.array() >= 0.0).all() || !(xi.array() <= 1.0).all())
        throw InputError("xi: (" + std::to_string(xi[0]) + ", " + std::to_string(xi[1]) +
                         ") is outside the element (0 <= xi1, xi2 <= 1)");
      X[i] = pair.undeformed.evaluate3(e, xi, sf::basis::kValues).x;
      x[i] = pair.deformed.evaluate3(e, xi, sf::basis::kValues).x;
      const sf::gsa::MarkStrain m = sf::gsa::strain_at(pair, sf::gsa::MeshLocation{e, xi}, result->fibre_angles);
      d1[i] = d2[i] = sf::Vec3::Constant(kNaN);
      if (m.strain) {
        const auto& s = *m.strain;
        l1[i] = s.lambda1, l2[i] = s.lambda2, e1[i] = s.green(0), e2[i] = s.green(1);
        g1[i] = s.engineering(0), g2[i] = s.engineering(1), t1[i] = s.true_strain(0), t2[i] = s.true_strain(1);
        th[i] = s.thickness_change_pct();
        d1[i] = s.dir1_deformed, d2[i] = s.dir2_deformed;
      }
      for (std::size_t f = 0; f < nf; ++f) {
        fdir[f][i] = sf::Vec3::Constant(kNaN);
        if (f < m.fibres.size()) fdir[f][i] = m.fibres[f].direction, fstretch[f][i] = m.fibres[f].stretch;
      }
      shear[i] = m.shear_angle_deg;
    }
    py::dict out;
    auto put = [&](const char* name, const std::vector<double>& v) {
      out[name] = single ? py::object(py::float_(v[0])) : py::object(vector_array(v));
    };
    auto put3 = [&](const std::string& name, const std::vector<sf::Vec3>& v) {
      py::array_t<double> a = rows3(v);
      out[name.c_str()] = single ? py::object(a[py::int_(0)]) : py::object(a);
    };
    put3("X", X);
    put3("x", x);
    put("lambda1", l1), put("lambda2", l2), put("E1", e1), put("E2", e2), put("eng1", g1), put("eng2", g2);
    put("true1", t1), put("true2", t2), put("thickness_change_pct", th);
    put3("dir1", d1);
    put3("dir2", d2);
    for (std::size_t f = 0; f < nf; ++f) {
      put3("fibre" + std::to_string(f + 1), fdir[f]);
      put(("fibre" + std::to_string(f + 1) + "_stretch").c_str(), fstretch[f]);
    }
    if (nf == 2) put("shear_angle_deg", shear);
    return out;
  }
};

// The per-point columns (strains.csv's names and values), the summary (summary.json's
// content, as JSON text) and the fitted surfaces.
py::dict to_python(const sf::gsa::GridData& grid, sf::gsa::AnalysisResult&& result, const AnalyseFlags& flags,
                   const sf::gsa::RunInfo& info) {
  using namespace sf::gsa;
  const Index n = grid.n_points();
  const OutputOptions output = output_options(flags);
  auto shared = std::make_shared<AnalysisResult>(std::move(result));
  const AnalysisResult& r = *shared;
  std::vector<std::string> status(n);
  std::map<std::string, std::vector<double>> c;
  const char* scalar[] = {"element",  "xi1",
                          "xi2",      "lambda1",
                          "lambda2",  "E1",
                          "E2",       "eng1",
                          "eng2",     "true1",
                          "true2",    "thickness_change_pct",
                          "residual", "residual_undeformed"};
  for (const char* name : scalar) c[name].assign(n, kNaN);
  std::vector<sf::Vec3> d1(n, sf::Vec3::Constant(kNaN)), d2 = d1, d1u = d1;
  const std::size_t nf = r.fibre_angles.size() == 2 ? 2 : 0;
  std::vector<std::vector<sf::Vec3>> fdir(nf, d1);
  std::vector<std::vector<double>> fstretch(nf, std::vector<double>(n, kNaN));
  std::vector<double> shear(n, kNaN);
  for (Index p = 0; p < n; ++p) {
    const PointResult& pr = r.points[p];
    status[p] = pr.status;
    if (pr.element >= 0) {
      c["element"][p] = static_cast<double>(pr.element);
      c["xi1"][p] = pr.xi[0];
      c["xi2"][p] = pr.xi[1];
    }
    if (pr.strain) {
      const SurfaceStrain& s = *pr.strain;
      c["lambda1"][p] = s.lambda1, c["lambda2"][p] = s.lambda2;
      c["E1"][p] = s.green(0), c["E2"][p] = s.green(1);
      c["eng1"][p] = s.engineering(0), c["eng2"][p] = s.engineering(1);
      c["true1"][p] = s.true_strain(0), c["true2"][p] = s.true_strain(1);
      c["thickness_change_pct"][p] = s.thickness_change_pct();
      d1[p] = s.dir1_deformed, d2[p] = s.dir2_deformed, d1u[p] = s.dir1_undeformed;
    }
    c["residual"][p] = pr.residual;
    c["residual_undeformed"][p] = pr.residual_undeformed;
    for (std::size_t f = 0; f < nf && f < pr.fibres.size(); ++f)
      fdir[f][p] = pr.fibres[f].direction, fstretch[f][p] = pr.fibres[f].stretch;
    shear[p] = pr.shear_angle_deg;
  }
  py::dict columns;
  columns["id"] = py::cast(grid.ids);
  columns["status"] = py::cast(status);
  auto vec3_columns = [&](const std::string& base, const std::vector<sf::Vec3>& v) {
    for (int k = 0; k < 3; ++k) {
      std::vector<double> comp(n);
      for (Index p = 0; p < n; ++p) comp[p] = v[p][k];
      columns[(base + "_" + "xyz"[k]).c_str()] = vector_array(comp);
    }
  };
  for (const char* name : scalar) {
    columns[name] = vector_array(c[name]);
    if (std::string(name) == "thickness_change_pct") {
      vec3_columns("dir1", d1);
      vec3_columns("dir2", d2);
      vec3_columns("dir1u", d1u);
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    vec3_columns("fibre" + std::to_string(f + 1), fdir[f]);
    columns[("fibre" + std::to_string(f + 1) + "_stretch").c_str()] = vector_array(fstretch[f]);
  }
  if (nf == 2) columns["shear_angle_deg"] = vector_array(shear);

  py::dict out;
  out["columns"] = columns;
  out["summary_json"] = make_summary(grid, r, output, info).dump();
  out["warnings"] = py::cast(r.warnings);
  out["surface"] = r.method == Method::kSurface ? py::cast(Surface{shared}) : py::none();
  return out;
}

py::dict analyse_grid(sf::gsa::GridData grid, const AnalyseFlags& flags, const sf::gsa::RunInfo& info) {
  const sf::gsa::AnalyseOptions options = sf::gsa::analyse_options(flags);
  sf::gsa::AnalysisResult result;
  {
    py::gil_scoped_release release;  // other Python threads run during the analysis
    result = sf::gsa::analyse(grid, options);
  }
  // The same warning and refusal as `gsa analyse` (gsa/analysis_checks.hpp).
  if (!flags.mesh.empty()) sf::gsa::warn_uncovered_marks(result, flags.mesh);
  sf::gsa::refuse_if_nothing_analysed(result, grid, flags.method);
  return to_python(grid, std::move(result), flags, info);
}

py::dict analyse_arrays(const py::handle& undeformed, const py::handle& deformed, const py::handle& ids,
                        const py::handle& ij, const py::dict& options) {
  const AnalyseFlags flags = flags_from(options);
  sf::gsa::GridData g;
  g.undeformed = points_from(undeformed, "undeformed", -1);
  const Index n = g.undeformed.rows();
  g.deformed = points_from(deformed, "deformed", n);
  if (ids.is_none()) {
    for (Index p = 0; p < n; ++p) g.ids.push_back(std::to_string(p + 1));
  } else {
    for (const py::handle& id : ids) g.ids.push_back(py::str(id).cast<std::string>());
    if (static_cast<Index>(g.ids.size()) != n)
      throw InputError("ids: " + std::to_string(g.ids.size()) + " ids for " + std::to_string(n) + " marks");
    std::unordered_map<std::string, Index> seen;
    for (Index p = 0; p < n; ++p) {
      if (g.ids[p].empty()) throw InputError("ids: row " + std::to_string(p) + ": empty id");
      const auto [it, fresh] = seen.emplace(g.ids[p], p);
      if (!fresh)
        throw InputError("ids: id '" + g.ids[p] + "' repeated (rows " + std::to_string(it->second) + " and " +
                         std::to_string(p) + ")");
    }
  }
  if (!ij.is_none()) {
    const auto a = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(ij);
    if (!a || a.ndim() != 2 || a.shape(1) != 2 || a.shape(0) != n)
      throw InputError("ij: expected an integer array of shape (n, 2): grid row i and column j of each mark");
    g.has_ij = true;
    for (Index p = 0; p < n; ++p) g.i.push_back(a.data()[2 * p]), g.j.push_back(a.data()[2 * p + 1]);
  }
  for (Index p = 0; p < n; ++p) g.where.push_back("row " + std::to_string(p));
  g.sources = {"<arrays>"};
  g.units = flags.units;
  return analyse_grid(std::move(g), flags, sf::gsa::RunInfo{"sheetform.analyse(arrays)", {}});
}

py::dict analyse_files(const std::string& grid, const std::string& undeformed, const std::string& deformed,
                       const py::dict& options) {
  AnalyseFlags flags = flags_from(options);
  flags.grid = grid, flags.undeformed = undeformed, flags.deformed = deformed;
  const sf::gsa::GridReadOptions ro = sf::gsa::grid_read_options(flags);
  sf::gsa::GridData g;
  sf::gsa::RunInfo info;
  if (!grid.empty()) {
    g = sf::gsa::read_grid(grid, ro);
    info = {"sheetform.analyse('" + grid + "')", {grid}};
  } else {
    g = sf::gsa::read_grid_pair(undeformed, deformed, ro);
    info = {"sheetform.analyse('" + undeformed + "', '" + deformed + "')", {undeformed, deformed}};
  }
  return analyse_grid(std::move(g), flags, info);
}

// A results folder: strains.csv's columns (numbers as float arrays, NaN where empty; text
// columns as lists) and summary.json as JSON text.
py::dict read_results(const std::string& dir) {
  const sf::gsa::ResultsFolder folder = sf::gsa::read_results_folder(dir);
  const sf::io::CsvTable& t = folder.strains;
  py::dict columns;
  for (std::size_t col = 0; col < t.n_columns(); ++col) {
    std::vector<double> numbers(t.n_rows());
    // Labels stay text even when they look like numbers ("17").
    const std::string& name = t.names()[col];
    bool numeric = name != "id" && name != "status" && name != "flag_reason";
    for (std::size_t r = 0; r < t.n_rows() && numeric; ++r) {
      try {
        numbers[r] = t.number(r, col, true);
      } catch (const sf::Error&) {
        numeric = false;
      }
    }
    if (numeric) {
      columns[t.names()[col].c_str()] = vector_array(numbers);
    } else {
      std::vector<std::string> text(t.n_rows());
      for (std::size_t r = 0; r < t.n_rows(); ++r) text[r] = std::string(t.cell(r, col));
      columns[t.names()[col].c_str()] = py::cast(text);
    }
  }
  py::dict out;
  out["columns"] = columns;
  out["summary_json"] = folder.summary.is_null() ? std::string("null") : folder.summary.dump();
  out["has_surfaces"] = folder.has_surfaces;
  // surfaces.json (surface method): the fitted surfaces, evaluable anywhere as after analyse().
  out["surface"] = py::none();
  const std::string surfaces = (std::filesystem::path(dir) / "surfaces.json").string();
  if (std::filesystem::exists(surfaces)) {
    sf::gsa::FittedSurfaces f = sf::gsa::read_surfaces_file(surfaces);
    auto r = std::make_shared<sf::gsa::AnalysisResult>();
    r->method = sf::gsa::Method::kSurface;
    r->mesh = std::move(f.mesh);
    r->undeformed_parameters = std::move(f.undeformed);
    r->deformed_parameters = std::move(f.deformed);
    const auto& params = folder.summary.is_object() && folder.summary.contains("parameters")
                             ? folder.summary["parameters"]
                             : nlohmann::json::object();
    if (params.contains("fibre_angles_deg")) r->fibre_angles = params["fibre_angles_deg"].get<std::vector<double>>();
    out["surface"] = py::cast(Surface{r});
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "sheetform._core: the C++ side of the sheetform module (use `import sheetform`)";
  static py::exception<sf::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<sf::InputError> input_error(m, "InputError", error.ptr());
  static py::exception<sf::UsageError> usage_error(m, "UsageError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const sf::UsageError& e) {
      usage_error(e.what());
    } catch (const sf::InputError& e) {
      input_error(e.what());
    } catch (const sf::Error& e) {
      error(e.what());
    }
  });
  m.attr("version") = SF_VERSION;
  py::class_<Surface>(m, "Surface", "The two fitted surfaces (undeformed, deformed) over one mesh")
      .def_property_readonly("n_elements", &Surface::n_elements, "Number of elements of the mesh")
      .def("evaluate", &Surface::evaluate, py::arg("element"), py::arg("xi"),
           "Positions and strains at (element, xi): one point, or arrays of n elements and (n, 2) xi");
  m.def("analyse_arrays", &analyse_arrays, py::arg("undeformed"), py::arg("deformed"), py::arg("ids"), py::arg("ij"),
        py::arg("options"));
  m.def("analyse_files", &analyse_files, py::arg("grid"), py::arg("undeformed"), py::arg("deformed"),
        py::arg("options"));
  m.def("read_results", &read_results, py::arg("dir"));
}
