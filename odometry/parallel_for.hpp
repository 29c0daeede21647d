#pragma once
// A parallel loop over independent items for the places that split work by hand (the map's
// octree subtrees, the viewer's chunk files): body(i) for every i in [0, n), indices handed out
// in order from a shared counter to `threads` threads (the caller's own thread is one of them).
// Which thread runs an item never changes what the item produces, so results do not depend on
// the number of threads as long as each body(i) writes only its own output. The first exception
// a body throws stops the handing out of further items and is rethrown once every thread has
// joined.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace gvio {

// The number of threads to use: `requested` when positive, else the machine's cores; never more
// than `cap` nor fewer than 1.
[[nodiscard]] inline unsigned threadCount(int requested, unsigned cap) {
  const unsigned hw = std::max(1U, std::thread::hardware_concurrency());
  const unsigned want = requested > 0 ? static_cast<unsigned>(requested) : hw;
  return std::clamp(want, 1U, std::max(1U, cap));
}

template <class Body>
void parallelFor(std::size_t n, unsigned threads, Body&& body) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        body(i);
      } catch (...) {  // bad_alloc, a failed write
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  const std::size_t extra = std::min<std::size_t>(std::max(1U, threads), n) - (n > 0 ? 1 : 0);
  std::vector<std::thread> pool;
  pool.reserve(extra);
  for (std::size_t t = 0; t < extra; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace gvio
