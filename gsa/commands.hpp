#pragma once
// Registers the subcommands of `gsa` (one function per command; main.cpp stays thin).

namespace sf::cli {
class Program;
}

namespace sf::gsa {

void register_commands(sf::cli::Program& program);

}  // namespace sf::gsa
