#include "forming/case/schema.hpp"

namespace sf::forming {

int FormingCase::find_ply(const std::string& name) const {
  for (std::size_t i = 0; i < plies.size(); ++i)
    if (plies[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace sf::forming
