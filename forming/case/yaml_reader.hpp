#pragma once
// The YAML walking helpers of the case readers (forming/case/reader.cpp,
// contact_reader.cpp, diaphragm_reader.cpp), internal to forming/case: yaml-cpp appears in no
// other header. A Reader collects problems with their places while walking the
// document; every accessor returns what it could read (or nothing) and records a
// problem otherwise, so the walk goes on.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/case/problems.hpp"
#include "forming/case/schema.hpp"

namespace sf::forming::case_yaml {

// Type tests that are false for a node that is not there: yaml-cpp's own IsScalar() etc.
// throw InvalidNode on the "zombie" node a const operator[] returns for a missing key (the
// "cannot read: invalid node" with no place, which stopped the whole check).
inline bool is_scalar(const YAML::Node& n) { return n.IsDefined() && n.IsScalar(); }
inline bool is_map(const YAML::Node& n) { return n.IsDefined() && n.IsMap(); }
inline bool is_sequence(const YAML::Node& n) { return n.IsDefined() && n.IsSequence(); }
inline bool is_null(const YAML::Node& n) { return n.IsDefined() && n.IsNull(); }

inline SourcePlace place_of(const YAML::Node& n) {
  if (!n.IsDefined()) return {};
  const YAML::Mark m = n.Mark();
  if (m.is_null()) return {};
  return {m.line + 1, m.column + 1};
}

inline std::string describe(const YAML::Node& n) {
  if (!n.IsDefined()) return "nothing";
  switch (n.Type()) {
    case YAML::NodeType::Null:
      return "null";
    case YAML::NodeType::Scalar:
      return "'" + n.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    default:
      return "nothing";
  }
}

// Collects problems while walking the document; every accessor returns what it could
// read (or nothing) and records a problem otherwise, so the walk goes on.
class Reader {
 public:
  explicit Reader(std::vector<CaseProblem>& problems) : problems_(problems) {}

  void problem(ProblemKind kind, const YAML::Node& at, const std::string& message, const std::string& name = {}) {
    problems_.push_back({kind, place_of(at), message, name});
  }
  void problem(ProblemKind kind, SourcePlace at, const std::string& message) {
    problems_.push_back({kind, at, message, {}});
  }

  // `n` must be a mapping whose keys are all in `allowed` (no duplicates).
  bool mapping(const YAML::Node& n, const std::string& what, const std::vector<std::string>& allowed) {
    if (!n.IsDefined()) return false;  // missing: required() said so
    if (!is_map(n)) {
      problem(ProblemKind::kWrongType, n, what + ": expected a mapping (key: value), found " + describe(n));
      return false;
    }
    std::set<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        problem(ProblemKind::kUnknownKey, it->first,
                what + ": unknown key '" + key + "' (expected one of: " + list + ")");
      } else if (!seen.insert(key).second) {
        problem(ProblemKind::kDuplicate, it->first, what + ": key '" + key + "' given twice");
      }
    }
    return true;
  }

  std::optional<double> number(const YAML::Node& n, const std::string& what) {
    if (!n.IsDefined()) return std::nullopt;  // missing: required() said so
    if (!is_scalar(n)) {
      problem(ProblemKind::kWrongType, n, what + ": expected a number, found " + describe(n));
      return std::nullopt;
    }
    const std::string& s = n.Scalar();
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
      problem(ProblemKind::kWrongType, n, what + ": expected a finite number, found '" + s + "'");
      return std::nullopt;
    }
    return v;
  }

  std::optional<double> positive(const YAML::Node& n, const std::string& what, const std::string& unit) {
    const std::optional<double> v = number(n, what);
    if (v && !(*v > 0.0)) {
      problem(ProblemKind::kOutOfRange, n, what + ": expected a positive value (" + unit + "), found " + n.Scalar());
      return std::nullopt;
    }
    return v;
  }

  std::optional<double> non_negative(const YAML::Node& n, const std::string& what, const std::string& unit) {
    const std::optional<double> v = number(n, what);
    if (v && *v < 0.0) {
      problem(ProblemKind::kOutOfRange, n, what + ": expected a value >= 0 (" + unit + "), found " + n.Scalar());
      return std::nullopt;
    }
    return v;
  }

  std::optional<int> integer(const YAML::Node& n, const std::string& what, int lo, int hi) {
    if (!n.IsDefined()) return std::nullopt;  // missing: required() said so
    if (!is_scalar(n)) {
      problem(ProblemKind::kWrongType, n, what + ": expected an integer, found " + describe(n));
      return std::nullopt;
    }
    const std::string& s = n.Scalar();
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
      problem(ProblemKind::kWrongType, n, what + ": expected an integer, found '" + s + "'");
      return std::nullopt;
    }
    if (v < lo || v > hi) {
      problem(ProblemKind::kOutOfRange, n,
              what + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " + s);
      return std::nullopt;
    }
    return static_cast<int>(v);
  }

  std::optional<bool> boolean(const YAML::Node& n, const std::string& what) {
    if (!n.IsDefined()) return std::nullopt;  // missing: required() said so
    if (is_scalar(n)) {
      const std::string& s = n.Scalar();
      if (s == "true" || s == "yes" || s == "on") return true;
      if (s == "false" || s == "no" || s == "off") return false;
    }
    problem(ProblemKind::kWrongType, n, what + ": expected true or false, found " + describe(n));
    return std::nullopt;
  }

  std::optional<std::string> text(const YAML::Node& n, const std::string& what) {
    if (!n.IsDefined()) return std::nullopt;  // missing: required() said so
    if (!is_scalar(n) || n.Scalar().empty()) {
      problem(ProblemKind::kWrongType, n, what + ": expected a name, found " + describe(n));
      return std::nullopt;
    }
    return n.Scalar();
  }

  // A required key of mapping `parent`; records "missing" at the parent.
  YAML::Node required(const YAML::Node& parent, const std::string& key, const std::string& what) {
    const YAML::Node n = parent[key];
    if (!n.IsDefined()) problem(ProblemKind::kMissing, parent, what + ": missing required key '" + key + "'");
    return n;
  }

  // The shape every reader repeats: key `key` of mapping `parent` read by `read` (an
  // accessor above, or the like, given the key's node; it returns an optional and
  // records the problem, with the node's line and column, when the value is bad) into
  // `field`. optional_key: an absent key leaves `field` alone; required_key: an absent
  // key is recorded at `parent` as required() does. Both return false on a problem.
  template <class T, class Read>
  bool optional_key(const YAML::Node& parent, const std::string& key, T& field, Read read) {
    const YAML::Node n = parent[key];
    return !n.IsDefined() || store(read(n), field);
  }
  template <class T, class Read>
  bool required_key(const YAML::Node& parent, const std::string& key, const std::string& what, T& field, Read read) {
    const YAML::Node n = required(parent, key, what);
    return n.IsDefined() && store(read(n), field);
  }

  // One of `words` (its index), else the problem "`what`: expected `expected`, found ..."
  // (`expected` spells the choices out, e.g. "top or bottom").
  std::optional<int> choice(const YAML::Node& n, const std::string& what, const std::vector<std::string>& words,
                            const std::string& expected) {
    if (is_scalar(n)) {
      const auto it = std::find(words.begin(), words.end(), n.Scalar());
      if (it != words.end()) return static_cast<int>(it - words.begin());
    }
    problem(ProblemKind::kWrongType, n, what + ": expected " + expected + ", found " + describe(n));
    return std::nullopt;
  }

 private:
  template <class T, class V>
  static bool store(const std::optional<V>& v, T& field) {
    if (!v) return false;
    field = *v;
    return true;
  }

  std::vector<CaseProblem>& problems_;
};

// [a, b] of positive numbers, or [n1, n2] of integers.
inline bool pair_of(Reader& r, const YAML::Node& n, const std::string& what) {
  if (!is_sequence(n) || n.size() != 2) {
    r.problem(ProblemKind::kWrongType, n, what + ": expected a list of two values [x, y], found " + describe(n));
    return false;
  }
  return true;
}

// The required key "ply" of a condition or load: its name and index; false (with a
// problem recorded) when missing, not a name or not a ply of the case.
inline bool ply_of(Reader& r, const YAML::Node& b, const std::string& what, const FormingCase& spec, std::string& name,
                   int& index) {
  const YAML::Node p = r.required(b, "ply", what);
  if (!p.IsDefined()) return false;
  const auto text = r.text(p, what + " ply");
  if (!text) return false;
  name = *text;
  index = spec.find_ply(*text);
  if (index < 0) {
    r.problem(ProblemKind::kUnknownPly, p, what + ": unknown ply '" + *text + "'", *text);
    return false;
  }
  return true;
}

// The optional key "ramp" (linear, smooth or constant) into `ramp`; false on a bad value.
inline bool ramp_of(Reader& r, const YAML::Node& b, const std::string& what, Ramp& ramp) {
  const YAML::Node rp = b["ramp"];
  if (!rp.IsDefined()) return true;
  if (is_scalar(rp) && rp.Scalar() == "linear") {
    ramp = Ramp::kLinear;
  } else if (is_scalar(rp) && rp.Scalar() == "smooth") {
    ramp = Ramp::kSmooth;
  } else if (is_scalar(rp) && rp.Scalar() == "constant") {
    ramp = Ramp::kConstant;
  } else {
    r.problem(ProblemKind::kWrongType, rp, what + " ramp: expected linear, smooth or constant, found " + describe(rp));
    return false;
  }
  return true;
}

inline std::optional<Vec3> vector3(Reader& r, const YAML::Node& n, const std::string& what, const std::string& unit) {
  if (!is_sequence(n) || n.size() != 3) {
    r.problem(ProblemKind::kWrongType, n, what + ": expected [x, y, z] (" + unit + "), found " + describe(n));
    return std::nullopt;
  }
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    const auto c = r.number(n[i], what);
    if (!c) return std::nullopt;
    v[i] = *c;
  }
  return v;
}

}  // namespace sf::forming::case_yaml
