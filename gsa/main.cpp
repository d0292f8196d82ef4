// gsa: thin executable over the sf_gsa library.
#include "common/cli/app.hpp"
#include "common/core/memory.hpp"
#include "gsa/commands.hpp"

int main(int argc, char** argv) {
  // The noise estimate and the fits free and allocate again 1e5 x 42 probe matrices
  // (34 MB each) per pilot: reused instead of mapped afresh (common/core/memory.hpp).
  sf::keep_freed_memory();
  sf::cli::Program program("gsa", "gsa — see docs/ for usage");
  sf::gsa::register_commands(program);
  return program.main(argc, argv);
}
