#pragma once
// Registers `gsa compare` (gsa/compare.hpp) with the gsa program.

#include "common/cli/app.hpp"

namespace sf::gsa {

void add_compare_command(cli::Program& program);

}  // namespace sf::gsa
