#pragma once
// `gsa batch LIST_OR_FOLDER --out DIR -j N` and `gsa batch --collect DIR` (docs/batch.md).

namespace sf::cli {
class Program;
}

namespace sf::gsa {

void add_batch_command(sf::cli::Program& program);

}  // namespace sf::gsa
