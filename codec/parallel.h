// A minimal fork-join loop for the codec's independent per-patch work (decoding patch streams, inverse
// transforms): tasks 1.. on short-lived threads, task 0 on the caller's. Tasks must not throw.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace geomip::codec {

/// Calls f(i) for i in [0, n) on up to `max_threads` threads (0 = one per hardware thread), then joins.
template <typename F>
void parallel_for(int n, int max_threads, F&& f) {
  int threads = max_threads > 0 ? max_threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, std::max(n, 1));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) f(i);
    return;
  }
  std::atomic<int> next{0};
  const auto worker = [&] {
    for (int i = next++; i < n; i = next++) f(i);
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace geomip::codec
