#pragma once
// Registers the subcommands of `simform` (one function per command; main.cpp stays thin).

namespace sf::cli {
class Program;
}

namespace sf::forming {

void register_commands(sf::cli::Program& program);

}  // namespace sf::forming
