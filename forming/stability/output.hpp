#pragma once
// Outputs of `simform stability` (docs/forming.md, "Buckling stability"), written into one
// folder atomically (common/io/atomic_file.hpp): the folder is replaced only when every file
// was written.
//
//   growth_rate.csv                 one row per (wave direction, wavelength); units in the
//                                   comment lines at the top
//   summary.json                    inputs, background state, most unstable mode, verdict,
//                                   numerical check, units, outputs
//   stability_map_thickening.png    stable / unstable regions over kappa and tau,
//   stability_map_thinning.png      for a thickening and a thinning trellis flow
//   growth_rate_direction.png       G and G - D33 against the wave direction
// The pictures are skipped with `plots = false`.

#include <string>
#include <vector>

#include "forming/stability/analysis.hpp"

namespace sf::forming::stability {

struct OutputOptions {
  std::string out_dir;  // required
  bool plots = true;
  std::string command_line;  // recorded in summary.json
  std::string input_file;    // "" when everything came from options
  bool quiet = false;        // no status lines on stderr
};

// Writes the folder; returns the names of the files written. Throws sf::Error when a file
// cannot be written or no display can be had for the pictures (the folder is then untouched).
std::vector<std::string> write_stability_outputs(const StabilityResult& result, const OutputOptions& options);

}  // namespace sf::forming::stability
