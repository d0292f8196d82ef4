#include "forming/commands.hpp"

#include <CLI/CLI.hpp>
#include <iostream>

#include "common/cli/app.hpp"

namespace sf::forming {

void register_commands(sf::cli::Program& program) {
  program.add_command(
      "info", "Print version and build information", [](CLI::App&) {},
      [] {
        std::cout << "simform " << SF_VERSION << " (forming solver for fibre-reinforced plies)\n";
        return sf::cli::kExitOk;
      });
}

}  // namespace sf::forming
