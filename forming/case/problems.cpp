#include "forming/case/problems.hpp"

#include "common/core/error.hpp"

namespace sf::forming {

std::string to_string(ProblemKind kind) {
  switch (kind) {
    case ProblemKind::kUnreadable:
      return "unreadable";
    case ProblemKind::kUnknownKey:
      return "unknown-key";
    case ProblemKind::kDuplicate:
      return "duplicate";
    case ProblemKind::kMissing:
      return "missing";
    case ProblemKind::kWrongType:
      return "wrong-type";
    case ProblemKind::kOutOfRange:
      return "out-of-range";
    case ProblemKind::kUnknownMaterial:
      return "unknown-material";
    case ProblemKind::kUnknownPly:
      return "unknown-ply";
    case ProblemKind::kUnknownTool:
      return "unknown-tool";
    case ProblemKind::kConflict:
      return "conflict";
    case ProblemKind::kUnsupported:
      return "unsupported";
    case ProblemKind::kNothingHeld:
      return "nothing-held";
  }
  return "?";
}

std::string CaseCheck::located(std::size_t i) const {
  const CaseProblem& p = problems.at(i);
  return located_message(spec.file, p.place.line, p.place.column, p.message);
}

}  // namespace sf::forming
