// simform: thin executable over the sf_forming library.
#include "common/cli/app.hpp"
#include "common/core/memory.hpp"
#include "forming/commands.hpp"

int main(int argc, char** argv) {
  sf::keep_freed_memory();  // Newton iterations reallocate large buffers (common/core/memory.hpp)
  sf::cli::Program program("simform", "simform — see docs/ for usage");
  sf::forming::register_commands(program);
  return program.main(argc, argv);
}
