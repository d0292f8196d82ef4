#pragma once
// The photogrammetry subcommands of `gsa`: calibrate, digitise, synth-images
// (docs/digitise.md). Registered from gsa/commands.cpp.

namespace sf::cli {
class Program;
}

namespace sf::gsa::digitise {

void register_commands(sf::cli::Program& program);

}  // namespace sf::gsa::digitise
