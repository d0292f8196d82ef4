#include "gsa/commands.hpp"

#include <CLI/CLI.hpp>
#include <iostream>

#include "common/cli/app.hpp"

namespace sf::gsa {

void register_commands(sf::cli::Program& program) {
  program.add_command(
      "info", "Print version and build information", [](CLI::App&) {},
      [] {
        std::cout << "gsa " << SF_VERSION << " (grid strain analysis by surface fitting)\n";
        return sf::cli::kExitOk;
      });
}

}  // namespace sf::gsa
