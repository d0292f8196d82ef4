#pragma once
// `simform run --grid-out FILE`: the final positions of an n x n grid of marks on the TOP
// face of one ply, in the grid-file format of `gsa analyse` (CONTRACT.md): a comment line
// naming the ply and the case, then columns id,X,Y,Z,x,y,z,i,j (mm), id "m<i>_<j>",
// marks i, j = 0..n-1 spread evenly over the ply (reference X on the undeformed top
// face, x on the deformed one), so the simulated part can be analysed like a measured
// one. Written atomically. (A common grid-file writer in common/io will take over the
// CSV part.)
#include <string>

#include "common/core/types.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// body: the ply (case order = body index); n >= 2 marks per side.
void write_grid(const std::string& path, const FormingCase& spec, const Model& model, int body, const VecX& x, int n);

}  // namespace sf::forming
