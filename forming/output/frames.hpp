#pragma once
// The ParaView time series of a run (CONTRACT.md, docs/forming.md "Outputs"):
//
//   result.pvd             the collection: one DataSet per written step, time = load factor
//   steps/step_NNNN.vtu    one per written step (NNNN = step, 4 digits)
//
// Each brick is tessellated into samples_inplane^2 x samples_thickness hexahedra;
// point data "displacement" (mm); cell data at each cell's centre: "cauchy_stress"
// (6 components xx, yy, zz, xy, yz, xz, MPa), "fibre_direction" (unit, deformed:
// F a0 / |F a0|), "fibre_stretch" (|F a0|), "ply" (body index); with a constrained body
// also "pressure" (MPa, positive in compression) and "fibre_tension" (MPa), and the
// stress includes -p I + (T/J) a (x) a.
//
// With contact (forming/contact/), the ply frames also carry point data on the faces
// that are the slave side of a contact pair (bilinear interpolation of the face's n x n
// contact points, held constant beyond the outermost ones; where a face is in several
// pairs, the pair with the highest pressure there; elsewhere pressure, slip and rate 0):
// "contact_pressure" (MPa), "contact_gap" (mm; NaN where there is no partner or off the
// contact faces), "contact_slip" (accumulated inter-ply / tool slip, mm, vector) and
// "contact_slip_rate" (mm/s, vector). Each written step also has, as further parts of
// the same time step in result.pvd:
//   steps/tool_<name>_NNNN.vtu     each rigid tool's surface (triangles) where it moves
//                                  then, over the plies' region (part 1, 2, ...);
//   steps/contact_NNNN.vtu         the contact points of every pair on the slave ply
//                                  faces (vertex cells), point data "pressure" (MPa),
//                                  "gap" (mm; 0 where the point has no partner), "slip"
//                                  (accumulated tangential slip, mm, vector), "slip_rate"
//                                  (mm/s, vector), "shear" (friction traction on the ply,
//                                  MPa, vector), "pair" (index of the contact pair).
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/vtk_xml.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// `context`: with contact (SurfaceContact interactions), the point data also gets the
// contact fields on the slave ply faces (see header); null: none.
io::VolumeMesh tessellate(const Model& model, const VecX& x, int samples_inplane, int samples_thickness,
                          const InteractionContext* context = nullptr);

// "steps/step_NNNN.vtu" of step k.
std::string step_file_name(int k);

class FrameSeries {
 public:
  FrameSeries(const Model& model, int samples_inplane, int samples_thickness)
      : model_(model), samples_inplane_(samples_inplane), samples_thickness_(samples_thickness) {}

  // Writes step k (load factor lambda, positions x) into `out`; a frame of the same
  // name (a restarted run with other step counts) is replaced in the collection.
  // `context`: the time and rates the contact fields are evaluated with (tools placed at
  // context.time); null: no tool or contact parts.
  void write(const io::AtomicOutputDir& out, int k, double lambda, const VecX& x,
             const InteractionContext* context = nullptr);
  // A frame already in the output folder (kept by a restart).
  void keep(double lambda, const std::string& name) { frames_.emplace_back(lambda, name); }
  // A tool or contact part already in the output folder (kept by a restart).
  void keep_part(const io::PvdDataSet& part) { parts_.push_back(part); }
  // The tool and contact parts of every frame, in the order written.
  const std::vector<io::PvdDataSet>& parts() const { return parts_; }
  // (load factor, file name) of every frame, in the order written.
  const std::vector<std::pair<double, std::string>>& frames() const { return frames_; }
  // result.pvd listing them (and the tool and contact parts written by this run).
  void write_collection(const std::string& path) const;

 private:
  void write_contact_parts(const io::AtomicOutputDir& out, int k, double lambda, const VecX& x,
                           const InteractionContext& context);
  const Model& model_;
  int samples_inplane_, samples_thickness_;
  std::vector<std::pair<double, std::string>> frames_;
  std::vector<io::PvdDataSet> parts_;  // tool and contact parts (part >= 1)
};

}  // namespace sf::forming
