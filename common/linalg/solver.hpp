#pragma once
// Direct sparse linear solvers behind one interface. Which library does the
// work (SuiteSparse CHOLMOD / UMFPACK or Eigen) is an implementation detail of
// solver.cpp; nothing from SuiteSparse appears here.
//
// Back ends
//   kCholmod    CHOLMOD supernodal Cholesky A = L L^T. Symmetric positive
//               definite only; reads the lower triangle of A. The fill-reducing
//               permutation is applied here (tril(P A P^T) kept with a value map made at
//               the analysis: 16 bytes per stored entry), not by CHOLMOD's two
//               transposes per factorisation (solver.cpp, CholmodPermutedBackend). With
//               Ordering::kNatural and a lower triangle none of that: A is read in place
//               (lay it out in the order of permutation(): PatternAssembler::set_order).
//   kUmfpack    UMFPACK LU with partial pivoting. Any square nonsingular A.
//   kCholmodLdlt CHOLMOD simplicial A = L D L^T (no pivoting): symmetric, definite or
//               not, as long as no pivot vanishes; reads the lower triangle of A.
//   kMumps      MUMPS multifrontal LU with threshold partial pivoting (SYM = 0). Any square
//               nonsingular A. Needs MUMPS (Debian's libmumps-seq-dev) in the build.
//   kMumpsLdlt  MUMPS multifrontal A = P L D L^T P^T with threshold pivoting (1x1 and 2x2
//               pivots; SYM = 2): symmetric, definite or indefinite, singular only when A
//               is; reads the lower triangle of A. Needs MUMPS.
//   kEigenLDLT  Eigen SimplicialLDLT, A = P^T L D L^T P without pivoting.
//               Symmetric only; reads the lower triangle of A.
//   kEigenLU    Eigen SparseLU (COLAMD ordering). Any square nonsingular A.
//   kAuto       chosen from the MatrixProperty at construction:
//                 SPD                 -> kCholmod  (kEigenLDLT without SuiteSparse)
//                 symmetric indefinite-> kUmfpack  (kEigenLDLT without SuiteSparse)
//                 unsymmetric         -> kUmfpack  (kEigenLU without SuiteSparse)
//
// Error channels (STYLE.md): an unknown solver name or a back end that cannot
// handle the declared matrix property is bad input (sf::InputError, at parse
// time or construction); a singular or indefinite matrix is a numerical
// outcome, returned as a SolveReport with a status and a message.
//
// Typical use (Newton loop with a fixed mesh):
//   LinearSolver solver(SolverKind::kAuto, MatrixProperty::kSymmetricPositiveDefinite);
//   for (each iteration) {
//     SparseMatrix k = assemble_tangent(...);           // n x n, same pattern each time
//     const SolveReport& report = solver.factorize(k);  // analyses only the first time
//     if (!report.ok()) return handle(report);          // e.g. cut the load step
//     Eigen::MatrixXd du = solver.solve(residual);      // n x n_rhs
//   }

#include <Eigen/Core>
#include <memory>
#include <string>

#include "common/linalg/sparse.hpp"

namespace sf::linalg {

// kCholmod: CHOLMOD's supernodal Cholesky (dense blocks through BLAS);
// kCholmodSimplicial: its column-by-column Cholesky, which calls no BLAS and so
// can run on several threads at once (one solver per thread).
enum class SolverKind {
  kAuto,
  kCholmod,
  kCholmodSimplicial,
  kUmfpack,
  kEigenLDLT,
  kEigenLU,
  kCholmodLdlt,
  kMumps,
  kMumpsLdlt
};

// "auto", "cholmod", "cholmod-simplicial", "umfpack", "eigen-ldlt", "eigen-lu", "cholmod-ldlt",
// "mumps", "mumps-ldlt".
std::string to_string(SolverKind kind);

// Inverse of to_string(SolverKind) (exact, lower case). Throws sf::InputError
// for any other name; the message starts with `where` (e.g. "--solver" or
// "case.json:12:5") when it is not empty and lists the accepted names.
SolverKind parse_solver_kind(const std::string& name, const std::string& where = "");

// True when the back end is compiled in (kAuto, kEigenLDLT and kEigenLU
// always are; the CHOLMOD and UMFPACK ones need SuiteSparse, kMumps and kMumpsLdlt MUMPS).
bool solver_available(SolverKind kind);
// True when the back end reads only the lower triangle of A (the Cholesky and LDL^T
// ones), so a matrix stored as its lower triangle may be passed.
bool reads_lower_triangle(SolverKind kind);

// Fill-reducing ordering of the CHOLMOD, UMFPACK and MUMPS back ends (the Eigen ones use their own):
//   kDefault  CHOLMOD's choice: AMD, and METIS as well when AMD's fill looks high
//   kAmd      approximate minimum degree
//   kMetis    METIS nested dissection (through CHOLMOD)
//   kNesdis   CHOLMOD's nested dissection (METIS partitions, constrained minimum degree)
//   kNatural  none: A is factorised in the order given (a matrix already laid out in a
//             fill-reducing order, e.g. by PatternAssembler::set_order with the
//             permutation() of an earlier analysis). kCholmod with a lower triangle then
//             reads A in place at every factorisation (no permuted copy, no value map).
// UMFPACK: kDefault and kAmd give its AMD / COLAMD, kMetis and kNesdis its METIS.
// MUMPS: kDefault its own choice (AMF or SCOTCH by size: Debian's build has no METIS), kAmd
// AMD, kMetis and kNesdis SCOTCH's nested dissection. kNatural: CHOLMOD's natural ordering
// (no postorder), UMFPACK's none; MUMPS and the Eigen back ends take their default.
enum class Ordering { kDefault, kAmd, kMetis, kNesdis, kNatural };
// "default", "amd", "metis", "nesdis", "natural".
std::string to_string(Ordering ordering);
// Inverse of to_string(Ordering); sf::InputError otherwise (message starts with `where`).
Ordering parse_ordering(const std::string& name, const std::string& where = "");

// The BLAS under CHOLMOD's supernodal factorisation. With a threaded OpenBLAS
// (Debian's libopenblas0-pthread chosen by update-alternatives) each supernodal
// factorisation and solve runs on factorisation_threads() BLAS threads and on one thread
// between them (so idle BLAS threads do not compete with the element loop); with a serial
// BLAS on one. The BLAS-calling factorisations and solves (CHOLMOD supernodal, UMFPACK,
// MUMPS) of all LinearSolvers are serialised by one lock: the serial OpenBLAS is not safe
// to call from two threads at once.
// Threads for one factorisation: by default sf::default_threads() (SF_THREADS, else
// OMP_NUM_THREADS, else the cores; common/core/parallel.hpp); set_factorisation_threads(n)
// overrides it (n >= 1), e.g. from a command-line option.
void set_factorisation_threads(int threads);
int factorisation_threads();
// One line naming the BLAS and its threading, e.g.
// "OpenBLAS 0.3.21 DYNAMIC_ARCH NO_AFFINITY SkylakeX MAX_THREADS=64 (pthreads, 2 threads per factorisation)".
std::string blas_description();

// Freed factorisation memory kept for reuse between Newton iterations: the program calls
// sf::keep_freed_memory() (common/core/memory.hpp) at start-up; this library never does.

// What the caller knows about A. It selects the kAuto back end and is checked
// against explicit back ends (kCholmod and kEigenLDLT need symmetry).
enum class MatrixProperty { kSymmetricPositiveDefinite, kSymmetricIndefinite, kUnsymmetric };

// "spd", "symmetric-indefinite", "unsymmetric".
std::string to_string(MatrixProperty property);

// Outcome of LinearSolver::analyze_pattern / factorize (Ceres style: a failed
// factorisation is data, not an exception).
struct SolveReport {
  enum class Status {
    kOk,             // factorisation available; solve() may be called
    kSingular,       // numerically singular, or not positive definite for kCholmod
    kNotFactorized,  // nothing factorised yet (also: pattern analysed only)
    kFailed,         // anything else: non-square input, library error, out of memory
  };

  Status status = Status::kNotFactorized;
  std::string message;                  // empty when kOk; otherwise what went wrong
  SolverKind used = SolverKind::kAuto;  // back end doing the work (kAuto resolved)
  Index n_rows = 0;                     // size of the system (n x n)
  Index n_nonzeros = 0;                 // stored entries of A
  bool reused_analysis = false;         // factorize() kept the previous symbolic analysis
  double analyze_seconds = 0.0;         // symbolic analysis (0 when reused)
  double factor_seconds = 0.0;          // numeric factorisation
  double solve_seconds = 0.0;           // most recent solve() (all its right-hand sides)
  double factor_flops = 0.0;            // floating-point operations of the numeric factorisation
                                        // as the library counts them (CHOLMOD, UMFPACK), 0 when unknown
  double factor_nonzeros = 0.0;         // entries of the factor(s): nnz(L) (Cholesky, LDL^T), or
                                        // nnz(L) + nnz(U) (LU); 0 when unknown (the Eigen back ends)
  std::string ordering;                 // fill-reducing ordering the analysis used, e.g. "amd",
                                        // "metis", "nesdis", "colamd"; with UMFPACK also its strategy
                                        // ("amd, symmetric strategy"); empty when unknown
  int negative_pivots = -1;             // negative eigenvalues of A (its inertia, Sylvester's law)
                                        // from a symmetric indefinite factorisation that counts them
                                        // (MUMPS LDL^T); -1 when unknown
  int determinant_sign = 0;             // sign of det(A) (+1 or -1) from a factorisation that
                                        // computes it (MUMPS, ICNTL(33)); 0 when unknown or singular
  double library_bytes = 0.0;           // bytes the library holds after the factorisation (factor,
                                        // analysis, workspace: CHOLMOD's memory_inuse); 0 when unknown

  bool ok() const { return status == Status::kOk; }
  // One line, e.g. "cholmod n=900 nnz=4380: ok; analyse 0.0004 s, factor 0.0011 s, solve 0.0001 s"
  // or "umfpack n=100 nnz=452: singular (matrix is singular: ...); analysis reused, factor ...".
  std::string brief() const;
};

// "ok", "singular", "not-factorized", "failed".
std::string to_string(SolveReport::Status status);

// Direct solver for A X = B with a square sparse A (n x n) and a dense B
// (n x n_rhs). One factorisation serves any number of solve() calls.
// Not thread-safe. Movable, not copyable.
class LinearSolver {
 public:
  // Throws sf::InputError when `kind` is not compiled in, or needs symmetry
  // (kCholmod, kEigenLDLT) while `property` is kUnsymmetric.
  explicit LinearSolver(SolverKind kind = SolverKind::kAuto,
                        MatrixProperty property = MatrixProperty::kSymmetricPositiveDefinite);
  ~LinearSolver();
  // A moved-from solver may only be assigned to or destroyed.
  LinearSolver(LinearSolver&&) noexcept;
  LinearSolver& operator=(LinearSolver&&) noexcept;
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  // Symbolic analysis (fill-reducing ordering) of the pattern of a; values are
  // ignored by the Cholesky back ends. Drops any previous factorisation; on
  // success the status is kNotFactorized.
  const SolveReport& analyze_pattern(const SparseMatrix& a);

  // Fill-reducing ordering for the next analysis (CHOLMOD and UMFPACK back ends; ignored by
  // the Eigen ones). Drops the current analysis when it changes.
  void set_ordering(Ordering ordering);
  Ordering ordering() const;
  // Iterative refinement of solve() (UMFPACK: up to 2 steps by default, each a product
  // with A and another pair of triangular solves; ignored by the other back ends). Off
  // for a preconditioner, whose solves need not be exact: a third of the solve's cost.
  void set_refinement(bool on);
  // Working memory a numeric factorisation may use, megabytes (MUMPS's ICNTL(23); 0, the
  // default: as much as its analysis estimates; ignored by the other back ends). A
  // factorisation that would need more fails (kFailed) rather than swap.
  void set_memory_limit(int megabytes);

  // Numeric factorisation of a. Analyses first when no analysis exists or when
  // a's pattern (size, column pointers, row indices) differs from the analysed
  // one; otherwise reuses it (report.reused_analysis). The solver keeps its own
  // copy of a, so a may be a temporary (unless keep_copy(false)).
  const SolveReport& factorize(const SparseMatrix& a);

  // keep_copy(false): analyze_pattern() and factorize() keep a copy of a compressed a's
  // pattern only (4 bytes per entry, for the comparison above), not of its values
  // (8 more): the solver reads a itself, so a must stay alive, with the same values,
  // while solve(), residual() and matrix() of that factorisation are used (a
  // PatternAssembler's matrix between assemblies). Default true: a copy of a.
  void keep_copy(bool keep);
  // The fill-reducing order of the current analysis: row perm[k] of A is eliminated k-th
  // (kCholmod; empty for the other back ends and before an analysis). With
  // PatternAssembler::set_order(perm) the assembler lays out the matrix a kNatural
  // solver factorises as it is.
  std::vector<int> permutation() const;

  // X (n x n_rhs) with A X = B for B (n x n_rhs), all columns from the current
  // factorisation. Precondition: last_report().ok() and B.rows() == n
  // (debug-checked; in release a violated precondition returns NaNs). Records
  // solve_seconds in last_report(); if the back end fails, the status becomes
  // kFailed and the result is NaN.
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const;

  // B - A X (n x n_rhs) with the solver's own copy of the last factorised A (read as its
  // lower triangle when the back end reads only that one): the check of a solution and the
  // right-hand side of a refinement step, X += solve(B - A X).
  Eigen::MatrixXd residual(const Eigen::Ref<const Eigen::MatrixXd>& b,
                           const Eigen::Ref<const Eigen::MatrixXd>& x) const;
  // The solver's own copy of the last analysed or factorised A (compressed), or the
  // caller's A itself after keep_copy(false).
  const SparseMatrix& matrix() const;

  // Report of the last analyze_pattern / factorize (and solve timing).
  const SolveReport& last_report() const;
  // Back end doing the work: the requested kind with kAuto resolved.
  SolverKind kind() const;
  MatrixProperty property() const;
  // True when the last factorize() succeeded.
  bool is_factorized() const { return last_report().ok(); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sf::linalg
