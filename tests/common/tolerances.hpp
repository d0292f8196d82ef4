#pragma once
// Named tolerances for the common-library tests (STYLE.md: named tolerances in
// one header). Each says what it bounds and why it is that size. All are
// absolute unless the name ends in Rel (relative).

namespace sf::test {

// Fixed seed for every std::mt19937 in the tests (reproducible random inputs).
inline constexpr unsigned kSeed = 20240611u;

// Identities on O(1) numbers that hold exactly in exact arithmetic
// (interpolation conditions, partition of unity, evaluate vs evaluate3).
inline constexpr double kRoundoff = 1e-12;

// Exact reproduction of polynomials with O(1) coefficients (a few dozen flops).
inline constexpr double kPolynomialExact = 1e-10;

// Gauss-Legendre quadrature of polynomials of degree <= 2n-1 (sums of <= 32^3 terms).
inline constexpr double kQuadratureExact = 1e-13;
// A quadrature error counts as "detectably nonzero" when it matches the known
// Gauss error constant to this relative accuracy (so it is not roundoff).
inline constexpr double kQuadratureErrorConstantRel = 1e-3;

// Central finite differences: step and the error allowed for first
// derivatives of O(1) cubics (truncation h^2 f'''/6 ~ 2e-10, roundoff eps/h ~ 1e-11).
inline constexpr double kFdStep = 1e-5;
inline constexpr double kFdFirst = 1e-7;
// Second derivatives from values (3-point stencil): step and allowed error
// (roundoff eps/h^2 ~ 1e-8; truncation is zero for cubics in that variable).
inline constexpr double kFdSecondStep = 1e-4;
inline constexpr double kFdSecond = 1e-6;

// Mesh geometry and fields on meshes of size O(1..10) built from exact nodal
// parameters: flat-plane reproduction, continuity across shared edges.
inline constexpr double kGeometry = 1e-10;
inline constexpr double kContinuity = 1e-10;

// A discontinuity or error that a test expects to SEE must exceed this.
inline constexpr double kDetectable = 1e-6;

// Arc-length scale factors of a circular arc (cubic Hermite, 8 elements over
// 180 degrees) against the true arc length per element, relative (measured
// 3.3e-5 for the factors, 6e-5 for the radius at mid-element).
inline constexpr double kArcLengthRel = 1e-4;

// Area of a flat disk (8 sectors x 4 rings) against pi R^2, relative. The
// cubic Hermite circle with arc-length tangents (45 degree sectors) lies inside
// the true circle: measured deficit 1.08e-3, independent of the ring count.
inline constexpr double kDiskAreaRel = 2e-3;
// ... and the error falls at fourth order in the sector angle (measured 4.0):
// each doubling of the sectors must divide it by at least 2^kDiskAreaOrder.
inline constexpr double kDiskAreaOrder = 3.5;

// Unit normals compared between neighbouring elements / against the apex plane.
inline constexpr double kNormal = 1e-9;
// Unit normal at xi2 = 1e-6 from a collapsed apex against the apex tangent plane
// normal (the deviation is O(xi2)).
inline constexpr double kApexNormalLimit = 1e-4;

}  // namespace sf::test
