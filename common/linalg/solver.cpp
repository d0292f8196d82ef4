#include "common/linalg/solver.hpp"

#include <fmt/format.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <dlfcn.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/linalg/krylov.hpp"

// SuiteSparse is linked privately into sf_common; without it the kAuto choice
// falls back to Eigen's own solvers.
#if __has_include(<cholmod.h>) && __has_include(<umfpack.h>)
#define SF_LINALG_HAVE_SUITESPARSE 1
#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>
#else
#define SF_LINALG_HAVE_SUITESPARSE 0
#endif

// MUMPS (Debian's libmumps-seq-dev, the sequential build): defined by CMake when found
// (cmake/SfDependencies.cmake); without it the kMumps kinds are not available.
#ifndef SF_LINALG_HAVE_MUMPS
#define SF_LINALG_HAVE_MUMPS 0
#endif
#if SF_LINALG_HAVE_MUMPS
#include <dmumps_c.h>
#endif

namespace sf::linalg {

namespace {

using Status = SolveReport::Status;

struct NamedKind {
  SolverKind kind;
  const char* name;
};
constexpr NamedKind kSolverNames[] = {
    {SolverKind::kAuto, "auto"},
    {SolverKind::kCholmod, "cholmod"},
    {SolverKind::kCholmodSimplicial, "cholmod-simplicial"},
    {SolverKind::kUmfpack, "umfpack"},
    {SolverKind::kEigenLDLT, "eigen-ldlt"},
    {SolverKind::kEigenLU, "eigen-lu"},
    {SolverKind::kCholmodLdlt, "cholmod-ldlt"},
    {SolverKind::kMumps, "mumps"},
    {SolverKind::kMumpsLdlt, "mumps-ldlt"},
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Result of one back-end step.
struct Outcome {
  Status status = Status::kOk;
  std::string message;
};

// One factorisation library. analyze() and factorize() get the solver's own
// compressed copy of A, which outlives the factorisation (UMFPACK's solve
// reads A again for iterative refinement).
class Backend {
 public:
  virtual ~Backend() = default;
  virtual Outcome analyze(const SparseMatrix& a) = 0;
  virtual Outcome factorize(const SparseMatrix& a) = 0;
  // x = A^-1 b; false when the library reports a failure.
  virtual bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const = 0;
  // Flops of one numeric factorisation with the current analysis (0: unknown).
  virtual double factor_flops() const { return 0.0; }
  // Entries of the factor(s) of the last analysis or factorisation (0: unknown).
  virtual double factor_nonzeros() const { return 0.0; }
  // Fill-reducing ordering of the current analysis ("": unknown).
  virtual std::string ordering_used() const { return {}; }
  // Fill-reducing ordering of the next analysis (back ends with a choice).
  virtual void set_ordering(Ordering) {}
  // Iterative refinement of solves (back ends that do it: UMFPACK, 2 steps by default).
  virtual void set_refinement(bool) {}
  // Negative pivots of the last symmetric indefinite factorisation (-1: not known).
  virtual int negative_pivots() const { return -1; }
  // Sign of det(A) of the last factorisation (0: not known).
  virtual int determinant_sign() const { return 0; }
  // Working memory allowed a factorisation, megabytes (0: no limit; MUMPS only).
  virtual void set_memory_limit(int) {}
  // Fill-reducing order of the current analysis (row perm[k] of A eliminated k-th); empty
  // when the back end does not give it.
  virtual std::vector<int> permutation() const { return {}; }
  // Bytes the library holds (factor, symbolic analysis, workspace); 0: unknown.
  virtual double library_bytes() const { return 0.0; }
};

// OpenBLAS's thread control, looked up at run time (any BLAS may be installed as
// libblas.so.3): null when the BLAS is not OpenBLAS.
struct OpenBlas {
  void (*set_num_threads)(int) = nullptr;
  int (*get_parallel)() = nullptr;  // 0 sequential, 1 pthreads, 2 OpenMP
  char* (*get_config)() = nullptr;
  OpenBlas() {
    set_num_threads = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    get_parallel = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
    get_config = reinterpret_cast<char* (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_config"));
  }
  bool threaded() const { return set_num_threads && get_parallel && get_parallel() != 0; }
};

const OpenBlas& openblas() {
  static const OpenBlas o;
  return o;
}

// The OpenMP runtime's nesting control, looked up at run time (libgomp is loaded when
// CHOLMOD, MUMPS or the program use OpenMP; sf_common itself is not compiled with it).
// CHOLMOD 3.0 (SuiteSparse 5.12) runs a few copying loops of each supernode (the map of its
// rows, A into L, the update added into L) as `parallel for num_threads(4)`, four threads
// whatever the cores or OMP_NUM_THREADS: on 2 cores, and worse on a loaded machine, each of
// those regions' fork and join cost more than the copy (measured: kernel and libgomp 37 % of
// the factorisation's samples). max-active-levels 0 makes every parallel region the calling
// thread meets inactive, one thread; libgomp keeps it per thread (GCC >= 11), so the other
// threads of the program are not affected.
struct OmpNesting {
  int (*get_max_active_levels)() = nullptr;
  void (*set_max_active_levels)(int) = nullptr;
  OmpNesting() {
    get_max_active_levels = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
    set_max_active_levels = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  }
  bool available() const { return get_max_active_levels && set_max_active_levels; }
};

const OmpNesting& omp_nesting() {
  static const OmpNesting o;
  return o;
}

std::atomic<int> g_factor_threads{0};

// Serialises the BLAS-calling (supernodal) factorisations and solves; while held, the
// BLAS runs on factorisation_threads() threads, and on one after. The libraries' own
// OpenMP regions run on the calling thread alone (OmpNesting) unless the BLAS itself is
// OpenMP-threaded (OpenBLAS's OpenMP build, whose threads those regions are).
class BlasSection {
 public:
  BlasSection() : lock_(mutex()) {
    if (openblas().threaded()) openblas().set_num_threads(factorisation_threads());
    const bool blas_uses_openmp = openblas().get_parallel && openblas().get_parallel() == 2;
    if (omp_nesting().available() && !blas_uses_openmp) {
      saved_levels_ = omp_nesting().get_max_active_levels();
      omp_nesting().set_max_active_levels(0);
    }
  }
  ~BlasSection() {
    if (saved_levels_ >= 0) omp_nesting().set_max_active_levels(saved_levels_);
    if (openblas().threaded()) openblas().set_num_threads(1);
  }
  BlasSection(const BlasSection&) = delete;
  BlasSection& operator=(const BlasSection&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  int saved_levels_ = -1;  // max-active-levels to restore; -1: left alone
};

#if SF_LINALG_HAVE_SUITESPARSE

// Eigen's wrapper keeps the CHOLMOD factor protected; the failing column
// (factor->minor) makes the "not positive definite" message useful.
template <class Wrapper>
class CholmodLlt : public Wrapper {
 public:
  const cholmod_factor* factor() const { return this->m_cholmodFactor; }
};

template <class Wrapper>
class CholmodBackend final : public Backend {
 public:
  explicit CholmodBackend(bool ldlt) : ldlt_(ldlt) {
    llt_.cholmod().print = 0;  // report through SolveReport
  }

  void set_ordering(Ordering ordering) override {
    cholmod_common& c = llt_.cholmod();
    c.postorder = ordering == Ordering::kNatural ? 0 : 1;
    if (ordering == Ordering::kDefault) {
      c.nmethods = 0;
      return;
    }
    c.nmethods = 1;
    c.method[0].ordering = ordering == Ordering::kNatural ? CHOLMOD_NATURAL
                           : ordering == Ordering::kAmd   ? CHOLMOD_AMD
                           : ordering == Ordering::kMetis ? CHOLMOD_METIS
                                                          : CHOLMOD_NESDIS;
  }

  Outcome analyze(const SparseMatrix& a) override {
    llt_.analyzePattern(a);
    const int status = llt_.cholmod().status;
    if (llt_.factor() == nullptr || status < CHOLMOD_OK) {
      return {Status::kFailed, fmt::format("CHOLMOD symbolic analysis failed (status {})", status)};
    }
    const cholmod_common& c = llt_.cholmod();
    flops_ = c.fl;
    lnz_ = c.lnz;
    const int selected = c.selected >= 0 && c.selected < CHOLMOD_MAXMETHODS ? c.selected : 0;
    switch (c.method[selected].ordering) {
      case CHOLMOD_NATURAL:
        ordering_ = "natural";
        break;
      case CHOLMOD_AMD:
        ordering_ = "amd";
        break;
      case CHOLMOD_METIS:
        ordering_ = "metis";
        break;
      case CHOLMOD_NESDIS:
        ordering_ = "nesdis";
        break;
      case CHOLMOD_COLAMD:
        ordering_ = "colamd";
        break;
      default:
        ordering_ = "given";
        break;
    }
    return {};
  }

  double factor_flops() const override { return flops_; }
  double factor_nonzeros() const override { return lnz_; }
  std::string ordering_used() const override { return ordering_; }

  Outcome factorize(const SparseMatrix& a) override {
    llt_.factorize(a);  // simplicial: no BLAS (the supernodal kind is CholmodPermutedBackend)
    if (llt_.info() == Eigen::Success) return {};
    const int status = llt_.cholmod().status;
    if (status < CHOLMOD_OK) {
      return {Status::kFailed, fmt::format("CHOLMOD numeric factorisation failed (status {}{})", status,
                                           status == CHOLMOD_OUT_OF_MEMORY ? ", out of memory" : "")};
    }
    const cholmod_factor* f = llt_.factor();
    if (ldlt_)
      return {Status::kSingular, fmt::format("zero pivot in LDL^T at {} of {} in elimination order (singular, or "
                                             "needs pivoting)",
                                             f->minor + 1, f->n)};
    return {Status::kSingular, fmt::format("matrix is not positive definite: Cholesky broke down at pivot {} of {} "
                                           "in elimination order; a symmetric indefinite matrix needs "
                                           "MatrixProperty::kSymmetricIndefinite",
                                           f->minor + 1, f->n)};
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    x = llt_.solve(b);
    return llt_.info() == Eigen::Success;
  }

 private:
  CholmodLlt<Wrapper> llt_;
  bool ldlt_ = false;
  double flops_ = 0.0;
  double lnz_ = 0.0;
  std::string ordering_;
};

// CHOLMOD's supernodal Cholesky of A (lower triangle given), with the fill-reducing
// permutation applied here rather than by CHOLMOD. Given a lower triangle and an ordering,
// cholmod_factorize builds tril(P A P^T) by two transposes of the whole matrix at every
// factorisation (cholmod_transpose_sym: measured 25 % of the 20x20x4 factorisation, as much
// as a third of its BLAS time); with the natural ordering and a lower triangle it reads the
// matrix as given. So the analysis runs twice: once on A for the ordering (AMD, METIS, ...,
// with CHOLMOD's postorder), then on B = tril(P A P^T) with the natural ordering (the same
// elimination tree and supernodes); each factorisation gathers A's values into B through a
// map made once, and each solve permutes the right-hand sides and solutions.
class CholmodPermutedBackend final : public Backend {
 public:
  CholmodPermutedBackend() {
    cholmod_start(&c_);
    c_.print = 0;  // report through SolveReport
    c_.supernodal = CHOLMOD_SUPERNODAL;
  }
  ~CholmodPermutedBackend() override {
    if (factor_ != nullptr) cholmod_free_factor(&factor_, &c_);
    cholmod_finish(&c_);
  }
  CholmodPermutedBackend(const CholmodPermutedBackend&) = delete;
  CholmodPermutedBackend& operator=(const CholmodPermutedBackend&) = delete;

  void set_ordering(Ordering ordering) override { ordering_choice_ = ordering; }

  Outcome analyze(const SparseMatrix& a) override {
    const int n = static_cast<int>(a.rows());
    // kNatural with a lower triangle: A is factorised as given (it is B), read in place by
    // every factorisation: no ordering, no copy, no map. When A is the B of the analysis
    // before (laid out in its permutation: PatternAssembler::set_order), that analysis of B
    // is kept.
    if (ordering_choice_ == Ordering::kNatural && factor_ != nullptr && !direct_ &&
        b_col_.size() == static_cast<std::size_t>(n) + 1 && b_row_.size() == static_cast<std::size_t>(a.nonZeros()) &&
        std::equal(b_col_.begin(), b_col_.end(), a.outerIndexPtr()) &&
        std::equal(b_row_.begin(), b_row_.end(), a.innerIndexPtr())) {
      go_direct();
      return {};
    }
    if (factor_ != nullptr) cholmod_free_factor(&factor_, &c_);
    direct_ = false;
    if (ordering_choice_ == Ordering::kNatural) {
      bool upper = false;
      for (int j = 0; j < n && !upper; ++j)
        upper = a.outerIndexPtr()[j + 1] > a.outerIndexPtr()[j] && a.innerIndexPtr()[a.outerIndexPtr()[j]] < j;
      if (!upper) {
        go_direct();
        return analyze_b(a, const_cast<int*>(a.outerIndexPtr()), const_cast<int*>(a.innerIndexPtr()), true);
      }
    }
    cholmod_sparse view = lower_view(a, const_cast<int*>(a.outerIndexPtr()), const_cast<int*>(a.innerIndexPtr()),
                                     nullptr, CHOLMOD_PATTERN);
    // 1. The ordering, on A (none for kNatural: A given with both triangles).
    if (ordering_choice_ == Ordering::kNatural) {
      c_.nmethods = 1;
      c_.method[0].ordering = CHOLMOD_NATURAL;
    } else if (ordering_choice_ == Ordering::kDefault) {
      c_.nmethods = 0;
    } else {
      c_.nmethods = 1;
      c_.method[0].ordering = ordering_choice_ == Ordering::kAmd     ? CHOLMOD_AMD
                              : ordering_choice_ == Ordering::kMetis ? CHOLMOD_METIS
                                                                     : CHOLMOD_NESDIS;
    }
    c_.postorder = ordering_choice_ == Ordering::kNatural ? 0 : 1;
    cholmod_factor* ordering_factor = cholmod_analyze(&view, &c_);
    if (ordering_factor == nullptr || c_.status < CHOLMOD_OK) {
      if (ordering_factor != nullptr) cholmod_free_factor(&ordering_factor, &c_);
      return {Status::kFailed, fmt::format("CHOLMOD symbolic analysis failed (status {})", c_.status)};
    }
    flops_ = c_.fl;
    lnz_ = c_.lnz;
    const int selected = c_.selected >= 0 && c_.selected < CHOLMOD_MAXMETHODS ? c_.selected : 0;
    const int used = c_.method[selected].ordering;
    ordering_ = used == CHOLMOD_NATURAL  ? "natural"
                : used == CHOLMOD_AMD    ? "amd"
                : used == CHOLMOD_METIS  ? "metis"
                : used == CHOLMOD_NESDIS ? "nesdis"
                : used == CHOLMOD_COLAMD ? "colamd"
                                         : "given";
    const int* perm = static_cast<const int*>(ordering_factor->Perm);
    inverse_.assign(static_cast<std::size_t>(n), 0);
    for (int k = 0; k < n; ++k) inverse_[static_cast<std::size_t>(perm[k])] = k;
    cholmod_free_factor(&ordering_factor, &c_);

    // 2. B = tril(P A P^T): entry p of A (row i >= column j) goes to B(max, min) of
    // (inverse[i], inverse[j]); entries above the diagonal of A (a matrix given with both
    // triangles) are not read. Columns counted, filled, then each sorted by row.
    const std::size_t nnz = static_cast<std::size_t>(a.nonZeros());
    const int* a_col = a.outerIndexPtr();
    const int* a_row = a.innerIndexPtr();
    b_col_.assign(static_cast<std::size_t>(n) + 1, 0);
    for (int j = 0; j < n; ++j)
      for (int p = a_col[j]; p < a_col[j + 1]; ++p)
        if (a_row[p] >= j)
          ++b_col_[static_cast<std::size_t>(std::min(inverse_[static_cast<std::size_t>(a_row[p])],
                                                     inverse_[static_cast<std::size_t>(j)])) +
                   1];
    for (int j = 0; j < n; ++j) b_col_[static_cast<std::size_t>(j) + 1] += b_col_[static_cast<std::size_t>(j)];
    const std::size_t b_nnz = static_cast<std::size_t>(b_col_[static_cast<std::size_t>(n)]);
    std::vector<int> next(b_col_.begin(), b_col_.end() - 1);
    b_row_.assign(b_nnz, 0);
    map_.assign(nnz, -1);  // -1: an entry above the diagonal
    std::vector<int> source(b_nnz);  // source[q]: entry of A that B's entry q holds
    for (int j = 0; j < n; ++j)
      for (int p = a_col[j]; p < a_col[j + 1]; ++p) {
        if (a_row[p] < j) continue;
        const int r = inverse_[static_cast<std::size_t>(a_row[p])], c = inverse_[static_cast<std::size_t>(j)];
        const int dst = next[static_cast<std::size_t>(std::min(r, c))]++;
        b_row_[static_cast<std::size_t>(dst)] = std::max(r, c);
        source[static_cast<std::size_t>(dst)] = p;
      }
    std::vector<std::pair<int, int>> column;
    for (int j = 0; j < n; ++j) {
      const int q0 = b_col_[static_cast<std::size_t>(j)], q1 = b_col_[static_cast<std::size_t>(j) + 1];
      column.clear();
      for (int q = q0; q < q1; ++q)
        column.emplace_back(b_row_[static_cast<std::size_t>(q)], source[static_cast<std::size_t>(q)]);
      std::sort(column.begin(), column.end());
      for (int q = q0; q < q1; ++q) {
        b_row_[static_cast<std::size_t>(q)] = column[static_cast<std::size_t>(q - q0)].first;
        map_[static_cast<std::size_t>(column[static_cast<std::size_t>(q - q0)].second)] = q;
      }
    }
    b_val_.assign(b_nnz, 0.0);

    // 3. The supernodal analysis of B in its own order.
    return analyze_b(a, b_col_.data(), b_row_.data(), false);
  }

  // The supernodal analysis of B (a's size, the given columns and rows) in its own order
  // (no postorder: P already has it, or the caller laid B out in its order).
  // From here on A is B, read in place: the permutation, the copy and its map are dropped.
  void go_direct() {
    release(inverse_);
    release(b_col_);
    release(b_row_);
    release(map_);
    release(b_val_);
    direct_ = true;
    ordering_ = "natural";
  }

  Outcome analyze_b(const SparseMatrix& a, int* col, int* row, bool counts) {
    cholmod_sparse b_view = lower_view(a, col, row, nullptr, CHOLMOD_PATTERN);
    c_.nmethods = 1;
    c_.method[0].ordering = CHOLMOD_NATURAL;
    c_.postorder = 0;
    factor_ = cholmod_analyze(&b_view, &c_);
    c_.postorder = 1;
    if (factor_ == nullptr || c_.status < CHOLMOD_OK) {
      if (factor_ != nullptr) cholmod_free_factor(&factor_, &c_);
      return {Status::kFailed, fmt::format("CHOLMOD symbolic analysis of the permuted matrix failed (status {})",
                                           c_.status)};
    }
    if (counts) {
      flops_ = c_.fl;
      lnz_ = c_.lnz;
    }
    return {};
  }

  std::vector<int> permutation() const override {
    std::vector<int> perm(inverse_.size());
    for (std::size_t i = 0; i < inverse_.size(); ++i) perm[static_cast<std::size_t>(inverse_[i])] = static_cast<int>(i);
    return perm;
  }
  double library_bytes() const override { return static_cast<double>(c_.memory_inuse); }

  double factor_flops() const override { return flops_; }
  double factor_nonzeros() const override { return lnz_; }
  std::string ordering_used() const override { return ordering_; }

  Outcome factorize(const SparseMatrix& a) override {
    if (factor_ == nullptr || (!direct_ && map_.size() != static_cast<std::size_t>(a.nonZeros())))
      return {Status::kFailed, "CHOLMOD factorisation without an analysis of this pattern"};
    const double* values = a.valuePtr();
    if (direct_) {
      // B is a itself.
    } else if (b_val_.size() == map_.size()) {  // a lower triangle: every entry has its place
      for (std::size_t p = 0; p < map_.size(); ++p) b_val_[static_cast<std::size_t>(map_[p])] = values[p];
    } else {
      for (std::size_t p = 0; p < map_.size(); ++p)
        if (map_[p] >= 0) b_val_[static_cast<std::size_t>(map_[p])] = values[p];
    }
    cholmod_sparse b_view =
        direct_ ? lower_view(a, const_cast<int*>(a.outerIndexPtr()), const_cast<int*>(a.innerIndexPtr()),
                             const_cast<double*>(values), CHOLMOD_REAL)
                : lower_view(a, b_col_.data(), b_row_.data(), b_val_.data(), CHOLMOD_REAL);
    {
      const BlasSection blas;
      cholmod_factorize(&b_view, factor_, &c_);
    }
    if (c_.status == CHOLMOD_NOT_POSDEF) {
      return {Status::kSingular, fmt::format("matrix is not positive definite: Cholesky broke down at pivot {} of {} "
                                             "in elimination order; a symmetric indefinite matrix needs "
                                             "MatrixProperty::kSymmetricIndefinite",
                                             factor_->minor + 1, factor_->n)};
    }
    if (c_.status < CHOLMOD_OK) {
      return {Status::kFailed, fmt::format("CHOLMOD numeric factorisation failed (status {}{})", c_.status,
                                           c_.status == CHOLMOD_OUT_OF_MEMORY ? ", out of memory" : "")};
    }
    return {};
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    const Eigen::Index n = b.rows();
    if (direct_) return solve_b(b, x);
    Eigen::MatrixXd pb(n, b.cols());
    for (Eigen::Index i = 0; i < n; ++i) pb.row(inverse_[static_cast<std::size_t>(i)]) = b.row(i);
    cholmod_dense* xd = solve_dense(pb.data(), n, b.cols());
    if (xd == nullptr) return false;
    const Eigen::Map<const Eigen::MatrixXd> px(static_cast<const double*>(xd->x), n, b.cols());
    x.resize(n, b.cols());
    for (Eigen::Index i = 0; i < n; ++i) x.row(i) = px.row(inverse_[static_cast<std::size_t>(i)]);
    cholmod_free_dense(&xd, &c_);
    return true;
  }

 private:
  // The factor's solve of the column-major rows x cols block at b (read only: cholmod_solve
  // copies it); the caller frees the result. nullptr when CHOLMOD fails.
  cholmod_dense* solve_dense(const double* b, Eigen::Index rows, Eigen::Index cols) const {
    cholmod_dense bd{};
    bd.nrow = static_cast<std::size_t>(rows);
    bd.ncol = static_cast<std::size_t>(cols);
    bd.nzmax = bd.nrow * bd.ncol;
    bd.d = bd.nrow;
    bd.x = const_cast<double*>(b);
    bd.xtype = CHOLMOD_REAL;
    bd.dtype = CHOLMOD_DOUBLE;
    const BlasSection blas;
    return cholmod_solve(CHOLMOD_A, factor_, &bd, &c_);
  }

  // x = B^-1 b (kNatural, lower triangle given: B is A).
  bool solve_b(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const {
    cholmod_dense* xd = solve_dense(b.data(), b.rows(), b.cols());
    if (xd == nullptr) return false;
    x = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(xd->x), b.rows(), b.cols());
    cholmod_free_dense(&xd, &c_);
    return true;
  }
  template <class T>
  static void release(std::vector<T>& v) {
    std::vector<T>().swap(v);
  }

  // A CHOLMOD view (no copy) of a lower triangle with a's size and the given arrays.
  static cholmod_sparse lower_view(const SparseMatrix& a, int* col, int* row, double* val, int xtype) {
    cholmod_sparse v{};
    v.nrow = static_cast<std::size_t>(a.rows());
    v.ncol = static_cast<std::size_t>(a.cols());
    v.nzmax = static_cast<std::size_t>(col[a.cols()]);
    v.p = col;
    v.i = row;
    v.x = val;
    v.stype = -1;
    v.itype = CHOLMOD_INT;
    v.xtype = xtype;
    v.dtype = CHOLMOD_DOUBLE;
    v.sorted = 1;
    v.packed = 1;
    return v;
  }

  mutable cholmod_common c_{};  // cholmod_solve takes it non-const (status, workspace)
  cholmod_factor* factor_ = nullptr;
  Ordering ordering_choice_ = Ordering::kDefault;
  bool direct_ = false;       // kNatural with a lower triangle: B is A (no map, no copy)
  std::vector<int> inverse_;  // inverse_[i]: position of A's row i in B
  std::vector<int> b_col_, b_row_, map_;
  std::vector<double> b_val_;
  double flops_ = 0.0;
  double lnz_ = 0.0;
  std::string ordering_;
};

// Eigen's wrapper keeps UMFPACK's Info array protected: factor sizes, flops, the ordering
// and strategy the analysis chose.
class UmfpackLu : public Eigen::UmfPackLU<SparseMatrix> {
 public:
  double umfpack_info(int field) const { return this->m_umfpackInfo(field); }
};

class UmfpackBackend final : public Backend {
 public:
  // UMFPACK's own choice: kDefault and kAmd use AMD (symmetric strategy) or COLAMD,
  // kMetis METIS; kNesdis (CHOLMOD's) is not UMFPACK's, so METIS stands in for it.
  void set_ordering(Ordering ordering) override {
    lu_.umfpackControl()(UMFPACK_ORDERING) =
        ordering == Ordering::kNatural                                ? UMFPACK_ORDERING_NONE
        : ordering == Ordering::kMetis || ordering == Ordering::kNesdis ? UMFPACK_ORDERING_METIS
                                                                      : UMFPACK_ORDERING_AMD;
  }

  void set_refinement(bool on) override { lu_.umfpackControl()(UMFPACK_IRSTEP) = on ? 2 : 0; }

  Outcome analyze(const SparseMatrix& a) override {
    lu_.analyzePattern(a);
    if (lu_.info() != Eigen::Success) {
      return {Status::kFailed, "UMFPACK symbolic analysis failed"};
    }
    const int ordering = static_cast<int>(lu_.umfpack_info(UMFPACK_ORDERING_USED));
    const int strategy = static_cast<int>(lu_.umfpack_info(UMFPACK_STRATEGY_USED));
    ordering_ = ordering == UMFPACK_ORDERING_AMD       ? (strategy == UMFPACK_STRATEGY_SYMMETRIC ? "amd" : "colamd")
                : ordering == UMFPACK_ORDERING_METIS   ? "metis"
                : ordering == UMFPACK_ORDERING_CHOLMOD ? "cholmod"
                : ordering == UMFPACK_ORDERING_NONE    ? "natural"
                                                       : "other";
    ordering_ += strategy == UMFPACK_STRATEGY_SYMMETRIC ? ", symmetric strategy" : ", unsymmetric strategy";
    return {};
  }

  double factor_flops() const override { return std::max(0.0, lu_.umfpack_info(UMFPACK_FLOPS)); }
  double factor_nonzeros() const override {
    return std::max(0.0, lu_.umfpack_info(UMFPACK_LNZ)) + std::max(0.0, lu_.umfpack_info(UMFPACK_UNZ));
  }
  std::string ordering_used() const override { return ordering_; }

  Outcome factorize(const SparseMatrix& a) override {
    {
      const BlasSection blas;  // UMFPACK's frontal matrices are BLAS calls
      lu_.factorize(a);
    }
    const int code = lu_.umfpackFactorizeReturncode();
    // Determinant under/overflow warnings do not affect the factors.
    if (code == UMFPACK_OK || code == UMFPACK_WARNING_determinant_underflow ||
        code == UMFPACK_WARNING_determinant_overflow) {
      return {};
    }
    if (code == UMFPACK_WARNING_singular_matrix) {
      return {Status::kSingular, "matrix is singular: UMFPACK found a zero pivot"};
    }
    return {Status::kFailed, fmt::format("UMFPACK numeric factorisation failed (status {}{})", code,
                                         code == UMFPACK_ERROR_out_of_memory ? ", out of memory" : "")};
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    const BlasSection blas;
    x = lu_.solve(b);
    return lu_.info() == Eigen::Success;
  }

 private:
  UmfpackLu lu_;
  std::string ordering_;
};

#endif  // SF_LINALG_HAVE_SUITESPARSE

#if SF_LINALG_HAVE_MUMPS

// MUMPS's multifrontal factorisation, sequential build (no MPI: its stub library stands in).
//   symmetric (kMumpsLdlt): SYM = 2, A = P L D L^T P^T with threshold pivoting (1x1 and 2x2
//     pivots), so a symmetric indefinite matrix needs no LU; reads the lower triangle.
//   unsymmetric (kMumps):   SYM = 0, LU with threshold partial pivoting.
// The analysis (ordering, elimination tree) is kept while the pattern stays; each
// factorisation passes the values only. Every call runs inside a BlasSection: MUMPS's dense
// kernels are BLAS calls, like CHOLMOD's supernodal ones.
// Controls other than the ordering and ICNTL(14) are MUMPS's defaults, measured on the dome's
// 10584-unknown tangent with the LU (processor seconds of one factorisation, analysis kept;
// data/forming/processes/README.md): ICNTL(7) = 7 picks SCOTCH (16.6 Gflop, 0.65 s; AMD and
// QAMD 22.5 Gflop, 0.80-0.84 s; PORD 19.8 Gflop, 0.73-0.76 s); ICNTL(6) (matching) and
// ICNTL(8) (scaling) off changed the time within the noise (0.60-0.67 s); ICNTL(10) = 2
// (MUMPS's iterative refinement) doubled the solve for a residual already at 1e-13 (the
// tangent solver checks each solution itself); ICNTL(24) = 1 (null-pivot detection)
// found none; ICNTL(14) = 20 against 30 left the peak memory unchanged (616 / 618 MB).
class MumpsBackend final : public Backend {
 public:
  explicit MumpsBackend(bool symmetric) : symmetric_(symmetric), id_(std::make_unique<DMUMPS_STRUC_C>()) { start(); }
  ~MumpsBackend() override {
    if (initialised_) call(-2);
  }
  MumpsBackend(const MumpsBackend&) = delete;
  MumpsBackend& operator=(const MumpsBackend&) = delete;

  // kDefault: MUMPS's own choice (ICNTL(7) = 7; Debian's build has SCOTCH and PORD but
  // not METIS, and picks AMF at the dome's sizes); kAmd: AMD; kMetis and kNesdis: SCOTCH's
  // nested dissection (the nested dissection Debian's MUMPS has).
  void set_ordering(Ordering ordering) override {
    ordering_choice_ = ordering == Ordering::kAmd                                          ? 0
                       : ordering == Ordering::kDefault || ordering == Ordering::kNatural ? 7
                                                                                          : 3;
  }

  Outcome analyze(const SparseMatrix& a) override {
    if (initialised_ && analysed_) {
      // A new pattern (contact grew it): MUMPS's instance ended and started afresh, so the
      // old factors and workspace are freed before the new analysis sizes larger ones (else
      // they were reallocated at the next factorisation while the old ones were still held).
      call(-2);
      initialised_ = false;
      start();
    }
    if (!initialised_) return {Status::kFailed, "MUMPS initialisation failed"};
    analysed_ = true;
    const int n = static_cast<int>(a.rows());
    rows_.clear();
    cols_.clear();
    take_.clear();
    rows_.reserve(static_cast<std::size_t>(a.nonZeros()));
    cols_.reserve(static_cast<std::size_t>(a.nonZeros()));
    bool all = true;
    for (int j = 0; j < n; ++j)
      for (int p = a.outerIndexPtr()[j]; p < a.outerIndexPtr()[j + 1]; ++p) {
        const int i = a.innerIndexPtr()[p];
        if (symmetric_ && i < j) {  // the upper triangle: the lower one holds it
          all = false;
          continue;
        }
        rows_.push_back(i + 1);
        cols_.push_back(j + 1);
        take_.push_back(p);
      }
    if (all) take_.clear();  // every entry, in order: pass the matrix's own values
    id_->n = n;
    id_->nnz = static_cast<MUMPS_INT8>(rows_.size());
    id_->irn = rows_.data();
    id_->jcn = cols_.data();
    id_->a = nullptr;
    icntl(7) = ordering_choice_;
    icntl(14) = kWorkspacePercent;
    call(1);
    if (id_->infog[0] < 0) return failure("symbolic analysis");
    const int used = infog(7);
    ordering_ = used == 0   ? "amd"
                : used == 2 ? "amf"
                : used == 3 ? "scotch"
                : used == 4 ? "pord"
                : used == 5 ? "metis"
                : used == 6 ? "qamd"
                            : "other";
    flops_ = rinfog(1);  // the analysis's estimate; the factorisation's count replaces it
    entries_ = static_cast<double>(infog(20));
    return {};
  }

  Outcome factorize(const SparseMatrix& a) override {
    if (take_.empty()) {
      id_->a = const_cast<double*>(a.valuePtr());  // MUMPS reads A, never writes it
    } else {
      values_.resize(take_.size());
      for (std::size_t k = 0; k < take_.size(); ++k) values_[k] = a.valuePtr()[take_[k]];
      id_->a = values_.data();
    }
    icntl(14) = kWorkspacePercent;
    icntl(23) = memory_limit_mb_;
    icntl(33) = 1;  // the determinant (O(n) products of the pivots): its sign for SF_NEWTON_TRACE
    for (int attempt = 0;; ++attempt) {
      call(2);
      const int code = id_->infog[0];
      // -8, -9: the workspace estimated by the analysis was too small (pivoting delayed
      // more than it foresaw): more and again.
      if ((code == -8 || code == -9) && attempt < 4) {
        icntl(14) *= 2;
        continue;
      }
      break;
    }
    if (id_->infog[0] == -10)
      return {Status::kSingular, "matrix is singular: MUMPS found it numerically singular (INFOG(1) = -10)"};
    if (id_->infog[0] < 0) return failure("numeric factorisation");
    flops_ = rinfog(3);
    const int e = infog(29);  // negative: millions
    entries_ = e >= 0 ? static_cast<double>(e) : -1e6 * static_cast<double>(e);
    negative_pivots_ = symmetric_ ? infog(12) : -1;
    // det = (RINFOG(12) + i RINFOG(13)) 2^INFOG(34), row and column permutations included.
    determinant_sign_ = rinfog(12) > 0.0 ? 1 : rinfog(12) < 0.0 ? -1 : 0;
    return {};
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    x = b;  // MUMPS overwrites the right-hand sides with the solutions
    id_->rhs = x.data();
    id_->nrhs = static_cast<int>(x.cols());
    id_->lrhs = static_cast<int>(x.rows());
    call(3);
    id_->rhs = nullptr;
    return id_->infog[0] >= 0;
  }

  double factor_flops() const override { return flops_; }
  double factor_nonzeros() const override { return entries_; }
  std::string ordering_used() const override { return ordering_; }
  int negative_pivots() const override { return negative_pivots_; }
  int determinant_sign() const override { return determinant_sign_; }
  void set_memory_limit(int megabytes) override { memory_limit_mb_ = megabytes; }

 private:
  static constexpr int kUseCommWorld = -987654;  // MUMPS's code for MPI_COMM_WORLD
  static constexpr int kWorkspacePercent = 30;   // ICNTL(14): extra workspace for delayed pivots

  MUMPS_INT& icntl(int i) { return id_->icntl[i - 1]; }
  void start() {
    *id_ = DMUMPS_STRUC_C{};
    id_->comm_fortran = kUseCommWorld;
    id_->par = 1;  // the host works (the only process)
    id_->sym = symmetric_ ? 2 : 0;
    call(-1);
    initialised_ = id_->infog[0] >= 0;
    if (!initialised_) return;
    icntl(1) = -1;  // no error, diagnostic, global or statistics output
    icntl(2) = -1;
    icntl(3) = -1;
    icntl(4) = 0;
  }
  int infog(int i) const { return id_->infog[i - 1]; }
  double rinfog(int i) const { return id_->rinfog[i - 1]; }
  void call(int job) const {
    const BlasSection blas;
    id_->job = job;
    dmumps_c(id_.get());
  }
  Outcome failure(const char* what) const {
    const int code = infog(1);
    return {Status::kFailed, fmt::format("MUMPS {} failed (INFOG(1) = {}, INFOG(2) = {}{})", what, code, infog(2),
                                         code == -13   ? ": out of memory"
                                         : code == -19 ? ": working memory above the limit set (ICNTL(23))"
                                         : code == -6  ? ": structurally singular"
                                                       : "")};
  }

  bool symmetric_ = false;
  bool initialised_ = false;
  bool analysed_ = false;               // an analysis was made by this instance of MUMPS
  std::unique_ptr<DMUMPS_STRUC_C> id_;  // MUMPS's state (large); solve() changes only its rhs fields
  std::vector<MUMPS_INT> rows_, cols_;  // 1-based coordinates of the entries passed
  std::vector<int> take_;               // their positions in A's values (empty: all, in order)
  std::vector<double> values_;
  int ordering_choice_ = 7;
  int memory_limit_mb_ = 0;  // ICNTL(23): 0, MUMPS's own estimate (no limit)
  std::string ordering_;
  double flops_ = 0.0;
  double entries_ = 0.0;
  int negative_pivots_ = -1;
  int determinant_sign_ = 0;
};

#endif  // SF_LINALG_HAVE_MUMPS

class EigenLdltBackend final : public Backend {
 public:
  Outcome analyze(const SparseMatrix& a) override {
    ldlt_.analyzePattern(a);
    if (ldlt_.info() != Eigen::Success) return {Status::kFailed, "LDL^T symbolic analysis failed"};
    return {};
  }

  Outcome factorize(const SparseMatrix& a) override {
    ldlt_.factorize(a);
    if (ldlt_.info() == Eigen::Success) return {};
    return {Status::kSingular, "zero pivot in LDL^T: matrix is singular or needs pivoting, try umfpack"};
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    x = ldlt_.solve(b);
    return ldlt_.info() == Eigen::Success;
  }

 private:
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
};

class EigenLuBackend final : public Backend {
 public:
  Outcome analyze(const SparseMatrix& a) override {
    // SparseLU's analysis (COLAMD ordering) reports nothing and leaves info()
    // from the previous factorisation in place, so there is nothing to check.
    lu_.analyzePattern(a);
    return {};
  }

  Outcome factorize(const SparseMatrix& a) override {
    lu_.factorize(a);
    switch (lu_.info()) {
      case Eigen::Success:
        return {};
      case Eigen::NumericalIssue:
        return {Status::kSingular, "matrix is singular: SparseLU: " + lu_.lastErrorMessage()};
      default:
        return {Status::kFailed, "SparseLU factorisation failed: " + lu_.lastErrorMessage()};
    }
  }

  bool solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const override {
    x = lu_.solve(b);
    return lu_.info() == Eigen::Success;
  }

 private:
  Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>> lu_;
};

SolverKind resolve_auto(MatrixProperty property) {
  switch (property) {
    case MatrixProperty::kSymmetricPositiveDefinite:
      return SF_LINALG_HAVE_SUITESPARSE ? SolverKind::kCholmod : SolverKind::kEigenLDLT;
    case MatrixProperty::kSymmetricIndefinite:
      return SF_LINALG_HAVE_SUITESPARSE ? SolverKind::kUmfpack : SolverKind::kEigenLDLT;
    case MatrixProperty::kUnsymmetric:
      return SF_LINALG_HAVE_SUITESPARSE ? SolverKind::kUmfpack : SolverKind::kEigenLU;
  }
  return SolverKind::kEigenLU;
}

std::unique_ptr<Backend> make_backend(SolverKind kind) {
  switch (kind) {
#if SF_LINALG_HAVE_SUITESPARSE
    case SolverKind::kCholmod:
      return std::make_unique<CholmodPermutedBackend>();
    case SolverKind::kCholmodSimplicial:
      return std::make_unique<CholmodBackend<Eigen::CholmodSimplicialLLT<SparseMatrix, Eigen::Lower>>>(false);
    case SolverKind::kCholmodLdlt:
      return std::make_unique<CholmodBackend<Eigen::CholmodSimplicialLDLT<SparseMatrix, Eigen::Lower>>>(true);
    case SolverKind::kUmfpack:
      return std::make_unique<UmfpackBackend>();
#endif
#if SF_LINALG_HAVE_MUMPS
    case SolverKind::kMumps:
      return std::make_unique<MumpsBackend>(false);
    case SolverKind::kMumpsLdlt:
      return std::make_unique<MumpsBackend>(true);
#endif
    case SolverKind::kEigenLDLT:
      return std::make_unique<EigenLdltBackend>();
    case SolverKind::kEigenLU:
      return std::make_unique<EigenLuBackend>();
    default:
      break;
  }
  SF_ASSERT(false, "make_backend: kind must be resolved and available");
  return std::make_unique<EigenLuBackend>();
}

// Same size and same compressed pattern (both arguments compressed).
bool same_pattern(const SparseMatrix& a, const SparseMatrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
  const int* a_outer = a.outerIndexPtr();
  const int* b_outer = b.outerIndexPtr();
  if (!std::equal(a_outer, a_outer + a.outerSize() + 1, b_outer)) return false;
  const int* a_inner = a.innerIndexPtr();
  return std::equal(a_inner, a_inner + a.nonZeros(), b.innerIndexPtr());
}

Eigen::MatrixXd nan_matrix(Eigen::Index rows, Eigen::Index cols) {
  return Eigen::MatrixXd::Constant(rows, cols, std::numeric_limits<double>::quiet_NaN());
}

}  // namespace

std::string to_string(SolverKind kind) {
  for (const NamedKind& named : kSolverNames) {
    if (named.kind == kind) return named.name;
  }
  return "unknown";
}

SolverKind parse_solver_kind(const std::string& name, const std::string& where) {
  std::string expected;
  for (const NamedKind& named : kSolverNames) {
    if (name == named.name) return named.kind;
    expected += expected.empty() ? "" : ", ";
    expected += named.name;
  }
  std::string message = fmt::format("unknown linear solver '{}' (expected one of: {})", name, expected);
  if (!where.empty()) message = where + ": " + message;
  throw InputError(message);
}

bool solver_available(SolverKind kind) {
  switch (kind) {
    case SolverKind::kCholmod:
    case SolverKind::kCholmodSimplicial:
    case SolverKind::kCholmodLdlt:
    case SolverKind::kUmfpack:
      return SF_LINALG_HAVE_SUITESPARSE != 0;
    case SolverKind::kMumps:
    case SolverKind::kMumpsLdlt:
      return SF_LINALG_HAVE_MUMPS != 0;
    default:
      return true;
  }
}

bool reads_lower_triangle(SolverKind kind) {
  switch (kind) {
    case SolverKind::kCholmod:
    case SolverKind::kCholmodSimplicial:
    case SolverKind::kCholmodLdlt:
    case SolverKind::kMumpsLdlt:
    case SolverKind::kEigenLDLT:
      return true;
    default:
      return false;
  }
}

std::string to_string(Ordering ordering) {
  switch (ordering) {
    case Ordering::kDefault:
      return "default";
    case Ordering::kAmd:
      return "amd";
    case Ordering::kMetis:
      return "metis";
    case Ordering::kNesdis:
      return "nesdis";
    case Ordering::kNatural:
      return "natural";
  }
  return "unknown";
}

Ordering parse_ordering(const std::string& name, const std::string& where) {
  for (Ordering o : {Ordering::kDefault, Ordering::kAmd, Ordering::kMetis, Ordering::kNesdis, Ordering::kNatural})
    if (name == to_string(o)) return o;
  std::string message =
      fmt::format("unknown fill-reducing ordering '{}' (expected one of: default, amd, metis, nesdis, natural)", name);
  if (!where.empty()) message = where + ": " + message;
  throw InputError(message);
}

void set_factorisation_threads(int threads) {
  SF_ASSERT(threads >= 0, "factorisation threads must be >= 0");
  g_factor_threads.store(threads);
}

int factorisation_threads() {
  const int n = g_factor_threads.load();
  if (n > 0) return n;
  return default_threads();  // SF_THREADS, else OMP_NUM_THREADS, else the cores
}

std::string blas_description() {
  const OpenBlas& o = openblas();
  if (!o.get_config) return "a BLAS other than OpenBLAS (threads not controlled)";
  std::string out = o.get_config();
  if (o.threaded())
    out += fmt::format(" ({}, {} thread{} per factorisation)", o.get_parallel() == 2 ? "OpenMP" : "pthreads",
                       factorisation_threads(), factorisation_threads() == 1 ? "" : "s");
  else
    out += " (sequential: 1 thread per factorisation)";
  return out;
}

std::string to_string(MatrixProperty property) {
  switch (property) {
    case MatrixProperty::kSymmetricPositiveDefinite:
      return "spd";
    case MatrixProperty::kSymmetricIndefinite:
      return "symmetric-indefinite";
    case MatrixProperty::kUnsymmetric:
      return "unsymmetric";
  }
  return "unknown";
}

std::string to_string(SolveReport::Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kSingular:
      return "singular";
    case Status::kNotFactorized:
      return "not-factorized";
    case Status::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string SolveReport::brief() const {
  std::string out = fmt::format("{} n={} nnz={}: {}", to_string(used), n_rows, n_nonzeros, to_string(status));
  if (!message.empty()) out += " (" + message + ")";
  out += reused_analysis ? fmt::format("; analysis reused") : fmt::format("; analyse {:.3g} s", analyze_seconds);
  out += fmt::format(", factor {:.3g} s, solve {:.3g} s", factor_seconds, solve_seconds);
  return out;
}

struct LinearSolver::Impl {
  SolverKind kind = SolverKind::kAuto;
  MatrixProperty property = MatrixProperty::kSymmetricPositiveDefinite;
  std::unique_ptr<Backend> backend;
  // Own compressed copy of the last analysed/factorised A: the pattern to
  // compare against, and the matrix UMFPACK reads during solve(). Without a copy
  // (keep_copy false): the caller's A (view) and its pattern (outer, inner).
  SparseMatrix matrix;
  bool keep_copy = true;
  const SparseMatrix* view = nullptr;
  std::vector<int> outer, inner;
  bool analysed = false;

  // The last analysed/factorised A.
  const SparseMatrix& a() const { return view ? *view : matrix; }
  // Takes a (compressed) as the current A: a copy, or a view and a copy of its pattern.
  void take(const SparseMatrix& a_new) {
    if (keep_copy || !a_new.isCompressed()) {
      view = nullptr;
      release_pattern();
      matrix = a_new;
      matrix.makeCompressed();
      return;
    }
    matrix = SparseMatrix();
    view = &a_new;
    view_rows = a_new.rows();
    outer.assign(a_new.outerIndexPtr(), a_new.outerIndexPtr() + a_new.outerSize() + 1);
    inner.assign(a_new.innerIndexPtr(), a_new.innerIndexPtr() + a_new.nonZeros());
  }
  void release_pattern() {
    std::vector<int>().swap(outer);
    std::vector<int>().swap(inner);
  }
  // a has the pattern of the current A (both compressed).
  bool same_as_current(const SparseMatrix& a_new) const {
    if (!view) return same_pattern(a_new, matrix);
    if (a_new.rows() != view_rows || a_new.cols() != view_rows ||
        static_cast<std::size_t>(a_new.nonZeros()) != inner.size() ||
        static_cast<std::size_t>(a_new.outerSize()) + 1 != outer.size())
      return false;
    return std::equal(outer.begin(), outer.end(), a_new.outerIndexPtr()) &&
           std::equal(inner.begin(), inner.end(), a_new.innerIndexPtr());
  }
  Index view_rows = 0;
  Ordering ordering = Ordering::kDefault;
  SolveReport report;

  // Starts a fresh report for `a`; false (and a kFailed report) if a is not square.
  bool begin_report(const SparseMatrix& a) {
    report = SolveReport{};
    report.used = kind;
    report.n_rows = a.rows();
    report.n_nonzeros = a.nonZeros();
    if (a.rows() != a.cols()) {
      report.status = Status::kFailed;
      report.message = fmt::format("matrix is not square ({} x {})", a.rows(), a.cols());
      analysed = false;
      return false;
    }
    return true;
  }

  // Analyses `matrix` and fills the report's analysis fields; false on failure.
  bool analyse() {
    const auto start = std::chrono::steady_clock::now();
    Outcome outcome = backend->analyze(a());
    report.analyze_seconds = seconds_since(start);
    analysed = outcome.status == Status::kOk;
    if (!analysed) {
      report.status = outcome.status;
      report.message = std::move(outcome.message);
    }
    return analysed;
  }
};

LinearSolver::LinearSolver(SolverKind kind, MatrixProperty property) : impl_(std::make_unique<Impl>()) {
  const bool needs_symmetry = reads_lower_triangle(kind);
  if (needs_symmetry && property == MatrixProperty::kUnsymmetric) {
    throw InputError(
        fmt::format("linear solver '{}' needs a symmetric matrix, but this system is unsymmetric "
                    "(use 'umfpack', 'eigen-lu' or 'auto')",
                    to_string(kind)));
  }
  if (!solver_available(kind)) {
    const bool mumps = kind == SolverKind::kMumps || kind == SolverKind::kMumpsLdlt;
    throw InputError(fmt::format("linear solver '{}' is not available: this build has no {} (use {})", to_string(kind),
                                 mumps ? "MUMPS (Debian's libmumps-seq-dev; scripts/install_deps.sh)" : "SuiteSparse",
                                 mumps ? "'umfpack', 'cholmod-ldlt' or 'auto'" : "'eigen-ldlt', 'eigen-lu' or 'auto'"));
  }
  impl_->kind = kind == SolverKind::kAuto ? resolve_auto(property) : kind;
  impl_->property = property;
  impl_->backend = make_backend(impl_->kind);
  impl_->report.used = impl_->kind;
  impl_->report.message = "nothing factorised yet";
}

LinearSolver::~LinearSolver() = default;
LinearSolver::LinearSolver(LinearSolver&&) noexcept = default;
LinearSolver& LinearSolver::operator=(LinearSolver&&) noexcept = default;

const SolveReport& LinearSolver::analyze_pattern(const SparseMatrix& a) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  Impl& im = *impl_;
  if (!im.begin_report(a)) return im.report;
  im.take(a);
  im.analysed = false;
  if (im.a().rows() == 0 || im.analyse()) {
    im.report.status = Status::kNotFactorized;
    im.report.message = "pattern analysed; not factorised yet";
  }
  return im.report;
}

void LinearSolver::set_ordering(Ordering ordering) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  if (impl_->ordering == ordering) return;
  impl_->ordering = ordering;
  impl_->backend->set_ordering(ordering);
  impl_->analysed = false;
  impl_->report = SolveReport{};
  impl_->report.used = impl_->kind;
  impl_->report.message = "nothing factorised yet";
}

void LinearSolver::set_refinement(bool on) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  impl_->backend->set_refinement(on);
}

void LinearSolver::set_memory_limit(int megabytes) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  SF_ASSERT(megabytes >= 0, "memory limit must be >= 0");
  impl_->backend->set_memory_limit(megabytes);
}

Ordering LinearSolver::ordering() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->ordering;
}

const SolveReport& LinearSolver::factorize(const SparseMatrix& a) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  Impl& im = *impl_;
  if (!im.begin_report(a)) return im.report;

  // Same pattern as the analysed matrix (the Newton case): copy the values only.
  bool reuse = false;
  if (im.analysed && a.isCompressed() && im.same_as_current(a)) {
    if (im.view)
      im.view = &a;
    else
      std::copy(a.valuePtr(), a.valuePtr() + a.nonZeros(), im.matrix.valuePtr());
    reuse = true;
  } else if (!im.keep_copy && a.isCompressed()) {
    im.take(a);  // a pattern that differs: analysed anew
  } else {
    SparseMatrix copy = a;
    copy.makeCompressed();
    reuse = im.analysed && im.same_as_current(copy);
    im.view = nullptr;
    im.release_pattern();
    im.matrix = std::move(copy);
  }
  if (im.a().rows() == 0) {  // nothing to factorise; solve() returns 0 x n_rhs
    im.analysed = false;
    im.report.status = Status::kOk;
    return im.report;
  }

  im.report.reused_analysis = reuse;
  if (!reuse && !im.analyse()) return im.report;

  const auto start = std::chrono::steady_clock::now();
  Outcome outcome = im.backend->factorize(im.a());
  im.report.factor_seconds = seconds_since(start);
  im.report.factor_flops = im.backend->factor_flops();
  im.report.factor_nonzeros = im.backend->factor_nonzeros();
  im.report.library_bytes = im.backend->library_bytes();
  im.report.ordering = im.backend->ordering_used();
  im.report.negative_pivots = im.backend->negative_pivots();
  im.report.determinant_sign = im.backend->determinant_sign();
  im.report.status = outcome.status;
  im.report.message = std::move(outcome.message);
  return im.report;
}

Eigen::MatrixXd LinearSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  Impl& im = *impl_;
  SF_ASSERT(im.report.ok(), "LinearSolver::solve() needs a successful factorize()");
  SF_ASSERT(b.rows() == im.a().rows(), "right-hand side has the wrong number of rows");
  if (!im.report.ok() || b.rows() != im.a().rows()) {
    return nan_matrix(im.a().rows(), b.cols());
  }
  if (im.a().rows() == 0 || b.cols() == 0) return Eigen::MatrixXd(im.a().rows(), b.cols());

  const auto start = std::chrono::steady_clock::now();
  const Eigen::MatrixXd rhs = b;  // contiguous column-major, as the libraries expect
  Eigen::MatrixXd x;
  const bool solved = im.backend->solve(rhs, x);
  im.report.solve_seconds = seconds_since(start);
  if (!solved) {
    im.report.status = Status::kFailed;
    im.report.message = fmt::format("{} reported an error while solving", to_string(im.kind));
    return nan_matrix(im.a().rows(), b.cols());
  }
  return x;
}

Eigen::MatrixXd LinearSolver::residual(const Eigen::Ref<const Eigen::MatrixXd>& b,
                                       const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  const Impl& im = *impl_;
  SF_ASSERT(b.rows() == im.a().rows() && x.rows() == b.rows() && x.cols() == b.cols(), "residual: wrong sizes");
  const bool lower = reads_lower_triangle(im.kind);
  // A back end that reads the lower triangle may have been given both: read only that one.
  bool upper = false;
  if (lower)
    for (Eigen::Index j = 0; j < im.a().outerSize() && !upper; ++j)
      for (SparseMatrix::InnerIterator it(im.a(), j); it && !upper; ++it) upper = it.row() < it.col();
  const SparseMatrix lower_copy = upper ? SparseMatrix(im.a().triangularView<Eigen::Lower>()) : SparseMatrix();
  const SparseMatrix& a = upper ? lower_copy : im.a();
  Eigen::MatrixXd r(b.rows(), b.cols());
  Eigen::VectorXd ax(b.rows());
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    multiply(a, lower ? Storage::kLower : Storage::kFull, x.col(c), ax);
    r.col(c) = b.col(c) - ax;
  }
  return r;
}

const SparseMatrix& LinearSolver::matrix() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->a();
}

void LinearSolver::keep_copy(bool keep) {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  Impl& im = *impl_;
  if (im.keep_copy == keep) return;
  im.keep_copy = keep;
  // The current A as the new setting keeps it (a view becomes a copy; a copy stays until
  // the next factorize() gives a matrix to view).
  if (keep && im.view) {
    im.matrix = *im.view;
    im.view = nullptr;
    im.release_pattern();
  }
}

std::vector<int> LinearSolver::permutation() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->analysed ? impl_->backend->permutation() : std::vector<int>();
}

const SolveReport& LinearSolver::last_report() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->report;
}

SolverKind LinearSolver::kind() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->kind;
}

MatrixProperty LinearSolver::property() const {
  SF_ASSERT(impl_ != nullptr, "use of a moved-from LinearSolver");
  return impl_->property;
}

}  // namespace sf::linalg
