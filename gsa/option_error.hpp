#pragma once
// Bad values in gsa's option structs (AnalyseOptions, OutputOptions). The library names
// the FIELD ("smoothing.scale"); the command layer knows which flag sets it and says that
// to the user ("--smoothing-scale: must be > 0, found 0").

#include <string>

#include "common/core/error.hpp"

namespace sf::gsa {

class OptionError : public UsageError {
 public:
  OptionError(std::string field, std::string problem)
      : UsageError(field + ": " + problem), field_(std::move(field)), problem_(std::move(problem)) {}
  // The field as written in code, e.g. "smoothing.scale" or "fibre_angles".
  const std::string& field() const { return field_; }
  // What was expected and what was found, e.g. "must be > 0, found 0".
  const std::string& problem() const { return problem_; }

 private:
  std::string field_, problem_;
};

}  // namespace sf::gsa
