#pragma once
// A loop over independent items on all cores (std::thread; blocks of items claimed
// in turn). Each item must write only its own results, so what the loop computes does
// not depend on the number of threads nor on the order the items are taken in.
// The first exception thrown by an item is rethrown once every thread has stopped.

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "common/core/types.hpp"

namespace sf {

namespace detail {
inline std::atomic<int>& thread_setting() {
  static std::atomic<int> setting{0};
  return setting;
}
}  // namespace detail

// Threads of both tools by default, the one setting: set_default_threads(n) when called
// with n >= 1 (e.g. from a command-line option), else the environment variable SF_THREADS
// when it is a whole number >= 1, else OMP_NUM_THREADS likewise (its first entry, as OpenMP
// reads it), else one per core. gsa's parallel loops (below), simform's element loop
// (forming::Model::threads, OpenMP) and the threads of one factorisation under a threaded
// BLAS (linalg::factorisation_threads) all start from it. Results never depend on it (see
// above): 1 and 2 threads give the same numbers to the last bit (tests:
// gsa.analysis.thread_count_*, the forming element loop's colouring).
inline void set_default_threads(int threads) { detail::thread_setting().store(threads > 0 ? threads : 0); }
namespace detail {
// The leading whole number of an environment variable if it is one in [1, 1024], else 0.
inline int threads_from_env(const char* name, bool leading_only) {
  const char* env = std::getenv(name);
  if (env == nullptr) return 0;
  char* end = nullptr;
  const long v = std::strtol(env, &end, 10);
  if (end == env || !(v >= 1 && v <= 1024)) return 0;
  if (*end != '\0' && !(leading_only && *end == ',')) return 0;
  return static_cast<int>(v);
}
}  // namespace detail
inline int default_threads() {
  if (const int set = detail::thread_setting().load(); set > 0) return set;
  if (const int sf = detail::threads_from_env("SF_THREADS", false); sf > 0) return sf;
  if (const int omp = detail::threads_from_env("OMP_NUM_THREADS", true); omp > 0) return omp;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// fn(i) for i in [0, n); `block` items at a time; `threads` 0 = default_threads().
template <class Fn>
void parallel_for(Index n, const Fn& fn, Index block = 256, int threads = 0) {
  if (n <= 0) return;
  int n_threads = threads > 0 ? threads : default_threads();
  n_threads = static_cast<int>(std::min<Index>(n_threads, (n + block - 1) / block));
  if (n_threads <= 1) {
    for (Index i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<Index> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    try {
      for (Index start = next.fetch_add(block); start < n; start = next.fetch_add(block))
        for (Index i = start; i < std::min(n, start + block); ++i) fn(i);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next.store(n);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace sf
