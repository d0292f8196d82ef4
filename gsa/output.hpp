#pragma once
// Writing the results of `gsa analyse` (CONTRACT.md): strains.csv, summary.json,
// undeformed.vtp, deformed.vtp and, with --sample, samples.csv. Everything is
// written into a temporary folder and moved into place only when all succeeded.

#include <nlohmann/json.hpp>
#include <string>

#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"

namespace sf::io {
class AtomicOutputDir;
}

namespace sf::gsa {

struct OutputOptions {
  std::string units = "mm";  // name of the grid's length unit, written into every file
  int sample = 0;            // > 0: also samples.csv with sample x sample points per element (<= 50)
  // Throws OptionError naming the field for a value out of range.
  void validate() const;
};

struct RunInfo {
  std::string command_line;
  std::vector<std::string> inputs;
};

// Column names of strains.csv, in order.
std::vector<std::string> strain_columns(const AnalysisResult& result);

void write_strains_csv(const std::string& path, const GridData& grid, const AnalysisResult& result,
                       const OutputOptions& options);
nlohmann::json make_summary(const GridData& grid, const AnalysisResult& result, const OutputOptions& options,
                            const RunInfo& info);
// Tessellated fitted surfaces (subdiv x subdiv quads per element) with the strain
// fields as point data; `deformed` selects the surface.
void write_surface_vtp(const std::string& path, const AnalysisResult& result, bool deformed, int subdiv = 8);
void write_samples_csv(const std::string& path, const AnalysisResult& result, const OutputOptions& options);

// Writes everything into `out` (not committed here).
void write_results(io::AtomicOutputDir& out, const GridData& grid, AnalysisResult& result,
                   const OutputOptions& options, const RunInfo& info);

}  // namespace sf::gsa
