#pragma once
// Pieces shared by the hyperelastic laws of this folder (neo_hookean.cpp,
// transversely_isotropic.cpp): parameter checks with the law's name in the message,
// fourth-order tensors in Voigt form (conventions of material.hpp), the coupled
// volumetric part and the response at an inverted point. Not part of the material
// interface; include it only from the laws' .cpp files.
#include <string>

#include "common/core/types.hpp"
#include "forming/material/material.hpp"

namespace sf::forming::detail {

// Voigt index pairs (11, 22, 33, 12, 23, 13).
inline constexpr int kVoigtPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

// Throws sf::InputError "<law> <parameter>: expected <expected>, found <found>".
[[noreturn]] void bad_parameter(const std::string& law, const std::string& parameter, const std::string& expected,
                                double found);
// A number with 10 significant digits, for messages.
std::string fmt(double v);
void require_finite(const std::string& law, const std::string& parameter, double v);
// Finite and > 0 ("a positive value (MPa)").
void require_positive(const std::string& law, const std::string& parameter, double v);

// X (x) Y in Voigt form.
Mat6 outer(const Mat3& X, const Mat3& Y);
// (X (.) X)_ijkl = (X_ik X_jl + X_il X_jk) / 2 in Voigt form (X symmetric).
Mat6 sym_product(const Mat3& X);

// The response at an inverted point (det C <= 0) of a law with a ln J term:
// W = +infinity, NaN stress and tangent.
MaterialResponse inverted_response();

// C symmetric to 1e-10 (debug checks of the laws' input).
bool is_symmetric(const Mat3& C);

// Coupled volumetric part shared by both laws, added to r:
//   W = -mu ln J + lambda/2 (ln J)^2, S = (lambda ln J - mu) Ci,
//   CC = lambda Ci (x) Ci + 2 (mu - lambda ln J) (Ci (.) Ci).
void add_volumetric(const Mat3& Ci, double ln_j, double mu, double lambda, bool want_tangent, MaterialResponse& r);

// The isotropic laws' (neo-Hookean, Mooney-Rivlin) shared volumetric step at C: checks C
// (debug), and adds add_volumetric() with Ci = C^-1, ln J = ln(det C)/2 and mu = m to r,
// which already holds the law's own invariant terms. False where det C <= 0 (the caller
// returns inverted_response()).
bool add_isotropic_volumetric(const char* law, const Mat3& C, double m, double lambda, bool want_tangent,
                              MaterialResponse& r);

// Isotropic small-strain Young's modulus from Lame constants.
double young_isotropic(double mu, double lambda);

}  // namespace sf::forming::detail
