#include "gsa/digitise/commands.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fnmatch.h>
#include <iostream>
#include <memory>
#include <sstream>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/grid_file.hpp"
#include "common/io/json.hpp"
#include "gsa/digitise/calibrate.hpp"
#include "gsa/digitise/digitise.hpp"
#include "gsa/digitise/example.hpp"

namespace sf::gsa::digitise {

namespace {

namespace fs = std::filesystem;

// "11x8" -> (11, 8).
std::pair<int, int> parse_pair(const std::string& text, const std::string& option, const char* what) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("x");
    std::size_t u1 = 0, u2 = 0;
    const int a = std::stoi(text.substr(0, x), &u1), b = std::stoi(text.substr(x + 1), &u2);
    if (u1 != x || u2 != text.size() - x - 1 || a < 1 || b < 1) throw std::invalid_argument("range");
    return {a, b};
  } catch (const std::exception&) {
    throw UsageError(option + ": expected " + what + ", found '" + text + "'");
  }
}

// "812.5,600" -> pixel.
Vec2 parse_point(const std::string& text, const std::string& option) {
  const auto c = text.find(',');
  try {
    if (c == std::string::npos) throw std::invalid_argument(",");
    std::size_t u1 = 0, u2 = 0;
    const double a = std::stod(text.substr(0, c), &u1), b = std::stod(text.substr(c + 1), &u2);
    if (u1 != c || u2 != text.size() - c - 1) throw std::invalid_argument("trailing");
    return Vec2(a, b);
  } catch (const std::exception&) {
    throw UsageError(option + ": expected a pixel X,Y of camera 0's image (e.g. 812,600), found '" + text + "'");
  }
}

bool is_image_name(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return e == ".png" || e == ".tif" || e == ".tiff" || e == ".jpg" || e == ".jpeg" || e == ".bmp" || e == ".pgm" ||
         e == ".ppm";
}

// A camera's images: a folder (its image files), a pattern with * ? [ in the file name, or a
// comma-separated list; sorted by name.
std::vector<std::string> expand_images(const std::string& spec, const std::string& what) {
  std::vector<std::string> out;
  std::error_code ec;
  if (spec.find(',') != std::string::npos) {
    std::stringstream ss(spec);
    std::string item;
    while (std::getline(ss, item, ','))
      if (!item.empty()) out.push_back(item);
    return out;
  }
  if (fs::is_directory(spec, ec)) {
    for (const auto& e : fs::directory_iterator(spec, ec))
      if (e.is_regular_file() && is_image_name(e.path())) out.push_back(e.path().string());
    if (out.empty())
      throw InputError(spec + ": no image files (png, tif, jpg, bmp, pgm) in this folder (" + what + ")");
  } else if (spec.find_first_of("*?[") != std::string::npos) {
    const fs::path p(spec);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    const std::string pattern = p.filename().string();
    if (dir.string().find_first_of("*?[") != std::string::npos)
      throw UsageError(spec + ": a pattern may only use * ? [ in the file name, not in folder names (" + what + ")");
    if (fs::is_directory(dir, ec))
      for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_regular_file() && fnmatch(pattern.c_str(), e.path().filename().c_str(), 0) == 0)
          out.push_back((dir / e.path().filename()).string());
    if (out.empty()) throw InputError(spec + ": no file matches (" + what + ")");
  } else {
    out.push_back(spec);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string fixed(double v, int digits) { return fmt::format("{:.{}f}", v, digits); }

void make_parent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
}

// ---------------------------------------------------------------------------------------
// calibrate

struct CalibrateArgs {
  std::vector<std::string> cameras;
  std::string out, target = "chessboard", pattern, units = "mm";
  double spacing = 0;
  bool k3 = false, zero_tangential = false, fix_aspect = false;
  int min_views = 3;
};

int run_calibrate(const CalibrateArgs& a, bool quiet) {
  CalibrateOptions o;
  if (a.target == "chessboard")
    o.target.kind = TargetKind::kChessboard;
  else if (a.target == "circles")
    o.target.kind = TargetKind::kCircles;
  else if (a.target == "acircles")
    o.target.kind = TargetKind::kAsymmetricCircles;
  else
    throw UsageError("--target: expected chessboard, circles or acircles, found '" + a.target + "'");
  std::tie(o.target.cols, o.target.rows) =
      parse_pair(a.pattern, "--pattern", "COLSxROWS (inner corners of a chessboard, circles of a grid), e.g. 9x6");
  o.target.spacing = a.spacing;
  o.fix_k3 = !a.k3;
  o.zero_tangential = a.zero_tangential;
  o.fix_aspect = a.fix_aspect;
  o.min_views = a.min_views;
  o.validate();
  if (a.cameras.empty()) throw UsageError("calibrate: give one folder (or pattern) of images per camera");
  std::vector<std::vector<std::string>> names;
  for (std::size_t c = 0; c < a.cameras.size(); ++c)
    names.push_back(expand_images(a.cameras[c], "camera " + std::to_string(c)));
  std::string counts;
  for (const auto& n : names) counts += (counts.empty() ? "" : " + ") + std::to_string(n.size());
  cli::status(quiet, fmt::format("gsa: calibrating {} camera{} from {} images ({})", names.size(),
                                 names.size() == 1 ? "" : "s", counts, o.target.describe(a.units)));
  CalibrationResult r = calibrate_rig(
      names, [&](std::size_t c, std::size_t k) { return read_image(names[c][k]); }, o);
  r.rig.units = a.units;
  r.rig.calibration_info = calibration_report(r, o);
  for (std::size_t c = 0; c < r.cameras.size(); ++c) {
    r.rig.cameras[c].name = "cam" + std::to_string(c);
    const CameraReport& cr = r.cameras[c];
    const Camera& cam = r.rig.cameras[c];
    int found = 0;
    for (const ImageReport& ir : cr.images) found += ir.found ? 1 : 0;
    cli::status(quiet,
                fmt::format("gsa: cam{} ({}, {} x {}): target in {} of {} images, {} used; RMS reprojection {} "
                            "px; fx {} fy {} cx {} cy {} px; k1 {} k2 {} p1 {} p2 {} k3 {}",
                            c, a.cameras[c], cr.width, cr.height, found, cr.images.size(), cr.n_used,
                            fixed(cr.rms_px, 3), fixed(cam.fx, 2), fixed(cam.fy, 2), fixed(cam.cx, 2), fixed(cam.cy, 2),
                            fixed(cam.distortion.k1, 5), fixed(cam.distortion.k2, 5), fixed(cam.distortion.p1, 6),
                            fixed(cam.distortion.p2, 6), fixed(cam.distortion.k3, 5)));
    for (const ImageReport& ir : cr.images)
      cli::status(quiet, "gsa:   " + ir.name + ": " +
                             (ir.found ? fixed(ir.rms_px, 3) + " px" + (ir.note.empty() ? "" : " (" + ir.note + ")")
                                       : ir.note));
  }
  for (const StereoReport& s : r.stereo) {
    cli::status(quiet,
                fmt::format("gsa: cam{} relative to cam0: {} image pairs, RMS reprojection {} px, baseline {} {}",
                            s.camera, s.n_pairs, fixed(s.rms_px, 3), fixed(s.baseline, 3), a.units));
    for (const std::string& d : s.dropped) cli::status(quiet, "gsa:   left out " + d);
  }
  make_parent(a.out);
  write_rig(a.out, r.rig);
  cli::status(quiet, "gsa: wrote " + a.out);
  return cli::kExitOk;
}

// ---------------------------------------------------------------------------------------
// digitise

struct DigitiseArgs {
  std::string calibration, out, report, marks = "dots", frame = "grid", centre = "centroid", seed, undeformed_seed,
                                        units;
  std::vector<std::string> deformed, undeformed;
  double pitch = 0, dot_diameter = 0, threshold = 0.35, mark_size = 0, epipolar = 2.0, max_reprojection = 1.0;
  int undeformed_rotate = 0;
  bool light_marks = false, no_bias_correction = false;
};

std::string set_summary(const SetResult& s) {
  return fmt::format("{} marks triangulated, RMS reprojection {} px (worst mark {} px){}", s.marks.size(),
                     fixed(s.rms_px, 3), fixed(s.max_rms_px, 3),
                     s.failed.empty() ? "" : fmt::format("; {} labelled but not triangulated", s.failed.size()));
}

void report_views(const SetResult& s, bool quiet) {
  for (const ViewReport& v : s.views) {
    std::string line = fmt::format("gsa: {}: {} marks labelled ({} candidates){}", v.name, v.n_labelled, v.n_candidates,
                                   v.has_reference ? fmt::format(", reference mark at ({:.1f}, {:.1f})",
                                                                 v.reference_pixel.x(), v.reference_pixel.y())
                                                   : ", no reference mark");
    if (!v.rejected.empty()) line += fmt::format("; {} not used (see --report)", v.rejected.size());
    if (!v.dropped.empty()) line += "; VIEW LEFT OUT: " + v.dropped;
    cli::status(quiet, line);
  }
}

int run_digitise(const DigitiseArgs& a, bool quiet) {
  DigitiseOptions o;
  if (a.marks == "dots")
    o.detect.kind = MarkKind::kDots;
  else if (a.marks == "lines")
    o.detect.kind = MarkKind::kLines;
  else
    throw UsageError("--marks: expected dots or lines, found '" + a.marks + "'");
  if (a.centre == "centroid")
    o.detect.centre = CentreMethod::kCentroid;
  else if (a.centre == "ellipse")
    o.detect.centre = CentreMethod::kEllipse;
  else
    throw UsageError("--centre: expected centroid or ellipse, found '" + a.centre + "'");
  if (a.frame != "grid" && a.frame != "rig") throw UsageError("--frame: expected grid or rig, found '" + a.frame + "'");
  if (a.undeformed_rotate % 90 != 0)
    throw UsageError("--undeformed-rotate: expected 0, 90, 180 or 270 degrees, found " +
                     std::to_string(a.undeformed_rotate));
  o.detect.dark_marks = !a.light_marks;
  o.detect.threshold = a.threshold;
  o.detect.mark_size_px = a.mark_size;
  o.match.tolerance_px = a.epipolar;
  o.triangulation.max_reprojection_px = a.max_reprojection;
  o.bias_correction = !a.no_bias_correction;
  o.dot_diameter_mm = a.dot_diameter;
  o.validate();
  if (a.deformed.empty()) throw UsageError("--deformed: give one image of the formed part per camera");
  if (!a.undeformed.empty() && a.pitch > 0)
    throw UsageError("give either --undeformed IMAGES (the flat blank) or --pitch MM (its printed pitch), not both");
  if (a.undeformed.empty() && !(a.pitch > 0))
    throw UsageError(
        "give --undeformed IMAGES (photographs of the flat blank) or --pitch MM (the printed pitch) for "
        "the undeformed positions");
  if (!a.undeformed_seed.empty() && a.undeformed.empty())
    throw UsageError("--undeformed-seed: only with --undeformed images");
  const Rig rig = read_rig(a.calibration);
  if (rig.n_cameras() < 2)
    throw InputError(a.calibration + ": the rig has " + std::to_string(rig.n_cameras()) +
                     " camera; digitising needs two or more calibrated cameras");
  const std::string units = a.units.empty() ? rig.units : a.units;

  auto run_set = [&](const std::vector<std::string>& paths, const std::string& option, const std::string& seed) {
    DigitiseOptions so = o;
    if (!seed.empty()) so.detect.seed = parse_point(seed, option == "--deformed" ? "--seed" : "--undeformed-seed");
    cli::status(quiet, "gsa: digitising " + option.substr(2) + " images");
    const auto images = read_image_set(rig, paths, option, a.calibration);
    SetResult s = digitise_set(rig, images, so);
    report_views(s, quiet);
    cli::status(quiet, "gsa: " + option.substr(2) + ": " + set_summary(s));
    return s;
  };
  std::optional<SetResult> und;
  if (!a.undeformed.empty()) und = run_set(a.undeformed, "--undeformed", a.undeformed_seed);
  const SetResult def = run_set(a.deformed, "--deformed", a.seed);
  if (und) {
    auto anchored = [](const SetResult& s, bool seeded) { return s.has_reference || seeded; };
    if (!anchored(*und, !a.undeformed_seed.empty()) || !anchored(def, !a.seed.empty()))
      throw InputError(fmt::format(
          "cannot join the flat blank's marks to the formed part's: camera 0 saw no reference mark in the {} images "
          "({}); print a reference mark (a dot of twice the area at the grid's origin, or for lines a dot in a cell), "
          "or give --seed X,Y and --undeformed-seed X,Y: pixels of the same mark in camera 0's two images",
          !anchored(*und, !a.undeformed_seed.empty()) ? "undeformed" : "deformed",
          !anchored(*und, !a.undeformed_seed.empty()) ? a.undeformed[0] : a.deformed[0]));
    if (a.undeformed_rotate != 0) {
      LabelTransform t = LabelTransform::identity(und->reference_lattice);
      t.symmetry = ((a.undeformed_rotate / 90) % 4 + 4) % 4;
      for (DigitisedMark& m : und->marks) m.ij = t.apply(m.ij);
    }
  }
  const Vec3 toward = rig.cameras[0].centre();
  const Eigen::Isometry3d Td = a.frame == "grid" ? grid_frame(def, toward) : Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d Tu = und && a.frame == "grid" ? grid_frame(*und, toward) : Eigen::Isometry3d::Identity();
  const std::vector<GridRow> rows = join_sets(und ? &*und : nullptr, Tu, def, Td, a.pitch);
  Index both = 0;
  for (const GridRow& r : rows) both += (r.undeformed.allFinite() && r.deformed.allFinite()) ? 1 : 0;

  std::vector<std::string> comments = {
      "grid file written by gsa digitise (docs/digitise.md)",
      "calibration: " + a.calibration,
      "undeformed: " + (und ? [&] {
        std::string s;
        for (const auto& p : a.undeformed) s += (s.empty() ? "" : " ") + p;
        return s;
      }()
                            : fmt::format("nominal, printed pitch {} {} (X = i pitch, Y = -j pitch, Z = 0)", a.pitch,
                                          units)),
      "deformed: " + [&] {
        std::string s;
        for (const auto& p : a.deformed) s += (s.empty() ? "" : " ") + p;
        return s;
      }(),
      a.frame == "grid" ? "frame: each state in its own grid frame: origin at mark (0, 0), X along +i, Z normal to "
                          "the marks' plane toward camera 0"
                        : "frame: the rig's (camera 0's) frame",
      "i, j: grid indices; i along camera 0's image rows, j down the image, (0, 0) at the reference mark",
      "views_*: cameras that saw the mark; reproj_*_px: its RMS reprojection error (pixels)"};
  if (a.out == "-") {
    write_grid(std::cout, rows, comments, units);
    std::cout.flush();
  } else {
    make_parent(a.out);
    io::write_file_atomic(a.out, [&](std::ostream& os) { write_grid(os, rows, comments, units); });
  }
  if (!a.report.empty()) {
    nlohmann::json j;
    j["calibration"] = a.calibration;
    j["units"] = units;
    j["marks"] = a.marks;
    if (und)
      j["undeformed"] = und->to_json();
    else
      j["undeformed"] = {{"nominal_pitch", a.pitch}};
    j["deformed"] = def.to_json();
    j["grid_rows"] = rows.size();
    j["rows_with_both_states"] = both;
    make_parent(a.report);
    io::write_json(a.report, j);
  }
  cli::status(quiet,
              fmt::format("gsa: wrote {}: {} marks, {} with both states{}", a.out == "-" ? "the grid to stdout" : a.out,
                          rows.size(), both, a.report.empty() ? "" : "; report in " + a.report));
  return cli::kExitOk;
}

// ---------------------------------------------------------------------------------------
// synth-images

struct SynthImagesArgs {
  std::string out, shape = "dome", marks = "dots", size = "1632x1224";
  int cameras = 2, views = 12;
  unsigned seed = 1;
  double noise = 1.5, blur = 0.7;
  bool occlusion = false, no_reference = false, even_lighting = false;
};

int run_synth_images(const SynthImagesArgs& a, bool quiet) {
  synth::ExampleOptions o;
  std::tie(o.width, o.height) = parse_pair(a.size, "--size", "WIDTHxHEIGHT in pixels, e.g. 1632x1224");
  if (o.width < 320 || o.height < 240) throw UsageError("--size: at least 320x240 pixels");
  if (a.shape == "dome")
    o.shape = synth::SheetShape::kDome;
  else if (a.shape == "bend")
    o.shape = synth::SheetShape::kBend;
  else if (a.shape == "flat")
    o.shape = synth::SheetShape::kFlat;
  else
    throw UsageError("--shape: expected dome, bend or flat, found '" + a.shape + "'");
  if (a.marks == "dots")
    o.marks = synth::PatternKind::kDots;
  else if (a.marks == "lines")
    o.marks = synth::PatternKind::kLines;
  else
    throw UsageError("--marks: expected dots or lines, found '" + a.marks + "'");
  if (a.cameras < 2 || a.cameras > 3) throw UsageError("--cameras: 2 or 3");
  if (a.views < 3 || a.views > 16) throw UsageError("--views: 3 to 16 calibration views");
  if (!(a.noise >= 0) || !(a.blur >= 0)) throw UsageError("--noise, --blur: expected values >= 0");
  o.n_cameras = a.cameras;
  o.calibration_views = a.views;
  o.occlusion = a.occlusion;
  o.reference = !a.no_reference;
  o.uneven_lighting = !a.even_lighting;
  o.effects.noise_sigma = a.noise / 255.0;
  o.effects.blur_sigma = a.blur;
  o.effects.seed = a.seed;

  const std::vector<Camera> cams = synth::example_cameras(o);
  const std::vector<synth::Scene> boards = synth::example_calibration_boards(o);
  const synth::Scene flat = synth::example_part(o, synth::SheetShape::kFlat);
  const synth::Scene formed = synth::example_part(o, o.shape);
  io::OutputDirOptions folder;
  folder.owned = {"calib", "flat", "formed", "truth.csv", "rig_true.json", "README.txt"};
  io::AtomicOutputDir out(a.out, folder);
  const long total = static_cast<long>(cams.size() * (boards.size() + 2));
  cli::Progress progress("gsa: rendering", total, quiet);
  long done = 0;
  auto render_to = [&](const Camera& cam, const synth::Scene& sc, unsigned seed, const std::string& name) {
    synth::Effects fx = o.effects;
    fx.seed = seed;
    write_png(out.path(name), synth::render(cam, sc, fx));
    progress.update(++done);
  };
  for (std::size_t c = 0; c < cams.size(); ++c) {
    for (std::size_t b = 0; b < boards.size(); ++b)
      render_to(cams[c], boards[b], a.seed * 1000 + 10 * static_cast<unsigned>(b) + static_cast<unsigned>(c),
                fmt::format("calib/cam{}/view_{:02d}.png", c, b));
    render_to(cams[c], flat, a.seed * 1000 + 500 + static_cast<unsigned>(c), fmt::format("flat/cam{}.png", c));
    render_to(cams[c], formed, a.seed * 1000 + 700 + static_cast<unsigned>(c), fmt::format("formed/cam{}.png", c));
  }
  progress.finish();
  // Ground truth: the grid file of exact positions (world frame = the blank's frame), with
  // the labels gsa digitise gives (i along camera 0's rows, j down its image) and the exact
  // stretches of the forming.
  const int dj = o.marks == synth::PatternKind::kLines ? 1 : 0;
  io::write_file_atomic(out.path("truth.csv"), [&](std::ostream& os) {
    io::GridWriteOptions wo;
    wo.comments = {"exact grid of the synthetic images (gsa synth-images); world frame = the flat blank's frame",
                   "formed shape: " + a.shape + "; lambda1 >= lambda2: exact principal stretches of the forming"};
    wo.units = "mm";
    wo.with_ij = true;
    wo.extra_columns = {"lambda1", "lambda2"};
    io::GridFileWriter w(os, wo);
    for (const synth::TrueMark& m : synth::true_marks(formed)) {
      const int i = m.i, j = dj - m.j;
      const Vec3 X = flat.sheet.position(Vec2(m.i * o.pitch, m.j * o.pitch));
      w.add(mark_id(i, j), X, m.position, i, j, {m.lambda1, m.lambda2});
    }
  });
  Rig truth;
  truth.cameras = cams;
  truth.calibration_info = {{"note", "the exact cameras of gsa synth-images (world frame = the flat blank's frame)"}};
  write_rig(out.path("rig_true.json"), truth);
  const synth::BoardSpec bs = synth::example_board(o);
  io::write_file_atomic(out.path("README.txt"), [&](std::ostream& os) {
    os << "Synthetic photographs written by: gsa synth-images --out " << a.out << " --shape " << a.shape << " --marks "
       << a.marks << " --size " << a.size << " --cameras " << a.cameras << " --views " << a.views << "\n\n"
       << "calib/camC/view_NN.png  chessboard " << bs.cols << "x" << bs.rows << " inner corners, " << bs.square
       << " mm squares\n"
       << "flat/camC.png           the flat blank\n"
       << "formed/camC.png         the formed part (" << a.shape << ")\n"
       << "truth.csv               exact mark positions (and stretches) for comparison\n"
       << "rig_true.json           the exact cameras\n";
  });
  out.commit();
  cli::status(quiet, fmt::format("gsa: wrote {} cameras x ({} calibration views + flat + formed) images of {} x {} "
                                 "pixels to {} (calibration target: --target chessboard --pattern {}x{} --spacing {})",
                                 cams.size(), boards.size(), o.width, o.height, a.out, bs.cols, bs.rows, bs.square));
  return cli::kExitOk;
}

}  // namespace

void register_commands(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto cal = std::make_shared<CalibrateArgs>();
  program.add_command(
      "calibrate",
      "Calibrate cameras (intrinsics, distortion, rig poses) from photographs of a chessboard or circle grid",
      [cal](CLI::App& app) {
        app.add_option("cameras", cal->cameras,
                       "Per camera: a folder of images, a quoted pattern ('calib/cam0_*.png') or a comma-separated "
                       "list; the cameras' images are paired by sorted name")
            ->required();
        app.add_option("-o,--out", cal->out, "Rig file to write (JSON, docs/digitise.md)")->required();
        app.add_option("--target", cal->target, "chessboard (default), circles or acircles (asymmetric circle grid)");
        app.add_option("--pattern", cal->pattern, "COLSxROWS: inner corners of the chessboard, or circles")->required();
        app.add_option("--spacing", cal->spacing, "Square size or circle spacing, in --units")->required();
        app.add_option("--units", cal->units, "Length unit of --spacing and of the rig (default mm)");
        app.add_flag("--k3", cal->k3, "Also estimate the radial coefficient k3 (wide-angle lenses)");
        app.add_flag("--zero-tangential", cal->zero_tangential, "Fix p1 = p2 = 0");
        app.add_flag("--fix-aspect", cal->fix_aspect, "Fix fx = fy");
        app.add_option("--min-views", cal->min_views, "Images per camera that must show the target (default 3)");
      },
      [cal, prog] { return run_calibrate(*cal, prog->common().quiet); });

  auto dig = std::make_shared<DigitiseArgs>();
  program.add_command(
      "digitise", "Grid marks from photographs of calibrated cameras to a grid file (flat blank and formed part)",
      [dig](CLI::App& app) {
        app.add_option("-c,--calibration", dig->calibration, "Rig file written by gsa calibrate")->required();
        app.add_option("--deformed", dig->deformed, "Images of the formed part, one per camera in the rig's order")
            ->required()
            ->expected(1, -1);
        app.add_option("--undeformed", dig->undeformed, "Images of the flat blank, one per camera")->expected(1, -1);
        app.add_option("--pitch", dig->pitch,
                       "Printed grid pitch: nominal undeformed positions instead of --undeformed");
        app.add_option("-o,--out", dig->out, "Grid file to write, or - for stdout (gsa analyse - reads it)")
            ->required();
        app.add_option("--report", dig->report, "Also write a JSON report: thresholds, rejected marks with reasons");
        app.add_option("--marks", dig->marks, "dots (default) or lines (junctions of a square line grid)");
        app.add_flag("--light-marks", dig->light_marks, "Marks lighter than the sheet");
        app.add_option("--centre", dig->centre, "Dot centres: centroid (default; grey-level) or ellipse");
        app.add_option("--threshold", dig->threshold,
                       "Contrast threshold of marks, fraction of the sheet's brightness (default 0.35)");
        app.add_option("--mark-size", dig->mark_size, "Dot diameter or grid cell size in pixels (default: measured)");
        app.add_option("--dot-diameter", dig->dot_diameter,
                       "Printed dot diameter, for the perspective-bias correction (default: measured)");
        app.add_flag("--no-bias-correction", dig->no_bias_correction,
                     "Do not correct the perspective bias of dot centres");
        app.add_option("--epipolar-tolerance", dig->epipolar,
                       "Pixels off the epipolar line still consistent (default 2)");
        app.add_option("--max-reprojection", dig->max_reprojection,
                       "Marks with a larger RMS reprojection error (px) are dropped (default 1)");
        app.add_option(
            "--frame", dig->frame,
            "grid (default: per state, origin at mark (0,0), X along i, Z the normal) or rig (camera 0's frame)");
        app.add_option("--seed", dig->seed,
                       "X,Y: a pixel of camera 0's formed-part image at mark (0,0), when no reference mark is printed");
        app.add_option("--undeformed-seed", dig->undeformed_seed, "X,Y: the same mark in camera 0's flat-blank image");
        app.add_option("--undeformed-rotate", dig->undeformed_rotate,
                       "Turn the flat blank's labels by 90, 180 or 270 degrees (blank photographed turned)");
        app.add_option("--units", dig->units, "Length unit written into the grid file (default: the rig's)");
      },
      [dig, prog] { return run_digitise(*dig, prog->common().quiet); });

  auto si = std::make_shared<SynthImagesArgs>();
  program.add_command(
      "synth-images",
      "Render synthetic photographs of a gridded sheet (flat and formed) and calibration views, with the exact answer",
      [si](CLI::App& app) {
        app.add_option("-o,--out", si->out, "Folder to write (calib/, flat/, formed/, truth.csv, rig_true.json)")
            ->required();
        app.add_option("--shape", si->shape, "Formed part: dome (default), bend or flat");
        app.add_option("--marks", si->marks, "dots (default) or lines");
        app.add_option("--size", si->size, "Image size WxH in pixels (default 1632x1224, 2 megapixels)");
        app.add_option("--cameras", si->cameras, "2 (default) or 3");
        app.add_option("--views", si->views, "Chessboard views per camera (default 12)");
        app.add_option("--noise", si->noise, "Image noise, standard deviation in 8-bit grey levels (default 1.5)");
        app.add_option("--blur", si->blur, "Optical blur, Gaussian sigma in pixels (default 0.7)");
        app.add_flag("--occlusion", si->occlusion, "A flap hiding marks and a trimmed corner cutting marks");
        app.add_flag("--no-reference", si->no_reference, "Print no reference mark");
        app.add_flag("--even-lighting", si->even_lighting, "No lighting fall-off or vignetting");
        app.add_option("--seed", si->seed, "Random seed of the noise (default 1)");
      },
      [si, prog] { return run_synth_images(*si, prog->common().quiet); });
}

}  // namespace sf::gsa::digitise
