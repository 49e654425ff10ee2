// A minimal fork-join loop for the codec's independent per-patch work (decoding patch streams, setting up
// bands, inverse transforms): tasks 1.. on short-lived threads, task 0 on the caller's.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace geomip::codec {

/// Calls f(i) for i in [0, n) on up to `max_threads` threads (0 = one per hardware thread), then joins.
/// When threads cannot be started the caller's thread does the remaining tasks. The first exception a task
/// throws is rethrown here after every thread has finished; tasks already running finish, no new one starts.
/// The codec's fork-join loop (its per-patch work, `geomip rd`'s jobs); param has its own (for_each_patch in
/// consistent_parameterization.cpp), which rethrows the lowest failing index's exception instead.
template <typename F>
void parallel_for(int n, int max_threads, F&& f) {
  int threads = max_threads > 0 ? max_threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, std::max(n, 1));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) f(i);
    return;
  }
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      try {
        f(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;  // start no further task
      }
    }
  };
  std::vector<std::thread> pool;
  try {
    pool.reserve(static_cast<std::size_t>(threads - 1));
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  } catch (const std::exception&) {  // std::system_error, std::bad_alloc: go on with the threads there are
  }
  worker();
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace geomip::codec
