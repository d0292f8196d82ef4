#pragma once
// STL triangle surfaces (stereolithography files), ASCII and binary.
//
// ASCII:                                   binary (little endian):
//   solid NAME                               80-byte header (any text, may start with "solid")
//     facet normal nx ny nz                  uint32 count
//       outer loop                           count x { float normal[3], float v[3][3],
//         vertex x y z   (three times)                   uint16 attribute }  (50 bytes each)
//       endloop
//     endfacet
//   endsolid NAME
// The kind is told from the content: a file of exactly 84 + 50 count bytes is binary
// (some binary files start their header with "solid"), otherwise it must be ASCII.
// Keywords are case-insensitive; several `solid` blocks may follow each other.
//
// The stored facet normals are ignored: what counts is the vertex order, counter-
// clockwise seen from the side the surface faces (its outward side), as the format
// prescribes. Vertices with bit-identical coordinates are welded into one (a facet's
// neighbours share its vertices), so vertex normals can be smoothed across facets.
// Facets of zero area (repeated or collinear vertices) are dropped and counted.
//
// Errors are sf::InputError naming the place in the STL file itself:
//   "die.stl:17:9: expected 'vertex', found 'vertx'"          (ASCII: line and column)
//   "die.stl: byte 134: vertex coordinate is not finite"       (binary: byte offset)
//   "die.stl: byte 84: expected 84 + 50 x 7 = 434 bytes ..."   (binary: size)
// Units: those of the file (the case file's, e.g. mm).

#include <array>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::io {

struct TriangleMesh {
  Points3 vertices;                             // n_vertices x 3, welded
  std::vector<std::array<Index, 3>> triangles;  // vertex indices, counter-clockwise from outside
  bool binary = false;                          // how the file was written
  std::string name;                             // ASCII: the first solid's name; binary: the header, trimmed
  Index dropped_degenerate = 0;                 // facets of zero area left out
};

// Reads an ASCII or binary STL file. Throws sf::InputError (see header) when the file
// cannot be opened, is malformed, or holds no facet of positive area.
TriangleMesh read_stl(const std::string& path);
// The same from bytes; `name` stands for the file in messages.
TriangleMesh read_stl_bytes(const std::string& bytes, const std::string& name);

// Writers (tests, samples): ASCII with full double precision, or binary (float).
void write_stl_ascii(const std::string& path, const TriangleMesh& mesh);
void write_stl_binary(const std::string& path, const TriangleMesh& mesh);

}  // namespace sf::io
