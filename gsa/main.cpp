// gsa: thin executable over the sf_gsa library.
#include "common/cli/app.hpp"
#include "gsa/commands.hpp"

int main(int argc, char** argv) {
  sf::cli::Program program("gsa", "gsa — see docs/ for usage");
  sf::gsa::register_commands(program);
  return program.main(argc, argv);
}
