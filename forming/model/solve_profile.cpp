#include "forming/model/solve_profile.hpp"

namespace sf::forming {

SolveProfile& solve_profile() {
  static SolveProfile profile;
  return profile;
}

}  // namespace sf::forming
