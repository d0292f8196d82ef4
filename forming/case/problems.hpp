#pragma once
// Problems found in a case file, as structured data: a kind, a place in the file, a
// message, and (for references to names) the name referred to. `simform check` lists
// them as FILE:LINE:COLUMN: message; the reader compares kinds and names, never the
// message text, when it drops follow-on problems (a ply naming a material that exists
// but is itself bad gets no "unknown material" problem).
#include <string>
#include <vector>

#include "forming/case/schema.hpp"

namespace sf::forming {

enum class ProblemKind {
  kUnreadable,       // not a readable file, or not valid YAML
  kUnknownKey,       // a key the format does not have (typos never pass silently)
  kDuplicate,        // a key, material or ply name given twice
  kMissing,          // a required key or section is absent
  kWrongType,        // expected a number, a name, a list of n values, a mapping, one of a set of words
  kOutOfRange,       // a value outside its range, or a material set the law cannot reach
  kUnknownMaterial,  // a ply names a material not defined (name = the material)
  kUnknownPly,       // a condition or load names a ply not defined (name = the ply)
  kUnknownTool,      // a contact names a tool not defined (name = the tool)
  kConflict,         // two boundary conditions prescribe a dof differently
  kUnsupported,      // a combination the solver does not handle (yet)
  kNothingHeld,      // no boundary condition holds any ply
};
// "unreadable", "unknown-key", ... (for tests and messages).
std::string to_string(ProblemKind kind);

struct CaseProblem {
  ProblemKind kind = ProblemKind::kWrongType;
  SourcePlace place;
  std::string message;
  std::string name;  // kUnknownMaterial, kUnknownPly: the name referred to
};

struct CaseCheck {
  FormingCase spec;                   // complete only when ok()
  std::vector<CaseProblem> problems;  // in file order
  bool ok() const { return problems.empty(); }
  // "FILE:LINE:COLUMN: message" for problem i.
  std::string located(std::size_t i) const;
};

}  // namespace sf::forming
