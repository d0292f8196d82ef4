#pragma once
// Pictures and report.html of `gsa compare` (docs/usage.md, "Comparing two analyses"):
//
//   diff_major.png, diff_minor.png, diff_thickness.png (and diff_shear_angle.png in fibre
//       mode): measured - simulated on the measured formed part, diverging colour map
//       centred on zero (blue: the measurement is below the simulation), units in the bar;
//       grey where the material point lies outside the simulated blank;
//   shape_deviation.png: the measured part's signed normal distance from the simulated
//       surface after registration (units of length);
//   position_difference.png: distance between the same material point on both parts
//       after registration (draw-in, sliding);
//   principal_strains.png: measured (blue) and simulated (orange) major against minor
//       strain of every matched mark, a grey line joining each mark's pair;
//   histogram.png: distribution of the major and minor strain differences;
//   histogram_shape.png: distribution of the shape deviation;
//   report.html: the summary (registration, blank map, counts, statistics, unmatched
//       marks) beside every picture.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gsa/compare.hpp"
#include "gsa/plots.hpp"

namespace sf::gsa {

// Writes the pictures to out_path(name); returns their names in report order.
std::vector<std::string> write_compare_pictures(const CompareSide& measured, const CompareSide& simulated,
                                                const CompareResult& result, const PlotOptions& options,
                                                const std::function<std::string(const std::string&)>& out_path,
                                                const PictureProgress& progress = {});

void write_compare_report(const std::string& path, const nlohmann::json& summary,
                          const std::vector<std::string>& pictures);

// compare.vtp: the measured formed part (tessellated, measured frame) with the differences
// as point data.
void write_compare_vtp(const std::string& path, const CompareResult& result);

}  // namespace sf::gsa
