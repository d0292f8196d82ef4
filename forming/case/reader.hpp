#pragma once
// Reading and checking case files of `simform` (YAML, read with yaml-cpp in reader.cpp
// only; the format is in docs/forming.md, the data in forming/case/schema.hpp).
//
// check_case_*() returns EVERY problem found, each with its kind and its place in the
// file (1-based line and column of yaml-cpp's Mark; forming/case/problems.hpp), sorted
// by place:
//   - per section while reading: unknown keys (typos), wrong types, values out of
//     range, unknown material or ply names, a law the constants cannot reach;
//   - across sections afterwards (forming/case/checks.hpp): what arc-length control and
//     dynamic analysis need, boundary conditions that prescribe a dof differently, and
//     a case that holds nothing.
// load_case() throws sf::InputError when there is any.
#include <string>

#include "forming/case/problems.hpp"
#include "forming/case/schema.hpp"

namespace sf::forming {

// Reads and validates a case file (a missing file is a problem too).
CaseCheck check_case_file(const std::string& path);
// Same from text; `name` stands for the file name in messages.
CaseCheck check_case_text(const std::string& text, const std::string& name);
// check_case_file(); throws sf::InputError with the first problem and the number of
// others ("run simform check") when there is any.
FormingCase load_case(const std::string& path);

}  // namespace sf::forming
