#pragma once
// report.html (one page: the summary beside all pictures) and strains.csv with the forming
// limit margin. Used by write_pictures() (plots.hpp).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/io/csv.hpp"
#include "gsa/plots.hpp"

namespace sf::gsa {

// A self-contained HTML page (inline style, no scripts, pictures referenced beside it by
// file name) with the summary.json content in tables and every picture in `plots`.
void write_report(const std::string& path, const nlohmann::json& summary, const std::string& case_name,
                  const PlotSummary& plots, const PlotOptions& options);

// Rewrites strains.csv (`table`, read from `original`) to `out` with a last column
// `flc_margin` (replacing one already there): margin[row] for each row, empty where NaN.
// The comment lines of the original are kept and one is added to describe the column.
void write_strains_with_margin(const io::CsvTable& table, const std::filesystem::path& original,
                               const std::string& out, const std::vector<double>& margin,
                               const std::string& measure_word, const std::string& flc_path);

}  // namespace sf::gsa
