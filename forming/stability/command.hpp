#pragma once
// `simform stability [INPUT.yaml] --out DIR [options]`: linear buckling stability of a trellis
// flow (docs/forming.md, "Buckling stability"). Options override the input file's values.
// Exit codes: 0 done (whatever the verdict), 1 bad input, 2 wrong usage.

namespace sf::cli {
class Program;
}

namespace sf::forming::stability {

// Registers the subcommand (its options and its run function) on `program`.
void add_stability_command(sf::cli::Program& program);

}  // namespace sf::forming::stability
