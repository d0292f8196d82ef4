#pragma once
// Thin helpers over nlohmann::json for summary files.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace sf::io {

// Writes `j` pretty-printed (2-space indent, trailing newline) atomically (write_file_atomic).
// NaN and infinities are written as null. Throws sf::Error naming the path on failure.
void write_json(const std::string& path, const nlohmann::json& j);

// Reads a JSON file. Throws sf::InputError "PATH: cannot open file (reason)" or
// "PATH:LINE:COLUMN: invalid JSON: ..." (COLUMN counted in bytes).
nlohmann::json read_json(const std::string& path);

// A matrix as an array of rows: rows() arrays of cols() numbers each (NaN becomes null
// when dumped). A 0 x n matrix gives [].
nlohmann::json to_json(const Eigen::Ref<const Eigen::MatrixXd>& m);

}  // namespace sf::io
