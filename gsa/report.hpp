#pragma once
// report.html: one page (inline style) with the summary.json content in tables beside
// every picture, which it references by file name (keep the folder together), and first
// the interactive 3-D view (gsa/view3d.hpp: its script and data inline).

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gsa/flc.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

struct ReportPage {
  std::string case_name;                         // e.g. "dome/grid.csv"
  StrainMeasure measure = StrainMeasure::kTrue;  // of the pictures
  std::vector<std::string> pictures;             // PNG file names, in page order
  const FlcMargins* flc = nullptr;               // the forming limit, when given
  std::string view3d_html;                       // the interactive 3-D view (gsa/view3d.hpp), first in <main>
  std::string view3d_note;                       // or why there is none
};

void write_report(const std::string& path, const nlohmann::json& summary, const ReportPage& page);

}  // namespace sf::gsa
