// Runs a loop body over [0, n) in contiguous chunks on std::threads.
// Host-only set-up code (volume resampling, derived proxies). Each chunk
// writes only its own outputs, so results never depend on the thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <thread>
#include <vector>

namespace mmrtm {

// Calls fn(begin, end) on `threads` threads (0: all hardware threads).
template <typename Fn>
void ParallelFor(int64_t n, int threads, Fn fn) {
  if (threads <= 0) threads = (int)std::max(1u, std::thread::hardware_concurrency());
  threads = (int)std::min<int64_t>(threads, std::max<int64_t>(n, 1));
  if (threads <= 1) {
    fn(int64_t(0), n);
    return;
  }
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(fn, n * t / threads, n * (t + 1) / threads);
  for (std::thread& t : pool) t.join();
}

// Calls worker(t) for t in [0, threads) (0: all hardware threads), worker
// 0 on the calling thread: the one that may report progress to a caller
// that is not thread-safe (a VTK observer, a terminal). Workers that share
// work take it from an atomic counter. Workers must not throw.
template <typename Fn>
void RunWorkers(int threads, Fn worker) {
  if (threads <= 0) threads = (int)std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace mmrtm
