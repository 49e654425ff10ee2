// Background fetch of a .gip pack from a local file or an http:// URL, coarse → fine: the fixed header, then
// the manifest, then the chunks in file order with HTTP range requests (libcurl). The bytes arrive in one
// buffer; the received prefix is published with an atomic counter, so readers on other threads may read
// data()[0 … received()) without a lock while the fetch goes on.
//
// Trusts nothing it reads: the manifest is checked against the source's real size (file size, Content-Length,
// Content-Range total) before anything is allocated (fetch_plan.h), the buffer is never larger than that size
// nor kMaxPackBytes, and bodies longer than asked for are cut. Errors and exceptions never leave the fetch
// thread: they end the fetch and are reported by error(). Cancelling (the destructor) takes effect within
// ~50 ms, also during --limit-rate pauses and on a stalled connection. HTTP redirects are followed (at most
// kMaxRedirects, http/https only); a server that ignores Range is read with the one GET it answered.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "stream_viewer/fetch_plan.h"

namespace geomip::viewer {

inline constexpr long kMaxRedirects = 5;

/// The block a --limit-rate of `rate` bytes/s lets in at once: ~1/10 s of it, 256 B to 16 KiB.
inline std::uint64_t rate_block(std::uint64_t rate) {
  return std::clamp<std::uint64_t>(rate / 10, 256, 16 << 10);
}

struct FetchOptions {
  /// Bytes per second, 0 = none: the bytes are let in at this pace in blocks of ~1/10 s of it (rate_block),
  /// as from a slow network, for files and HTTP alike (libcurl's own limit let a whole 64 KiB request in at
  /// once).
  std::uint64_t limit_rate = 0;
  std::uint64_t request_bytes = 64 << 10;  ///< chunks are grouped into range requests of about this size
  /// HTTP: a connection that delivers nothing for this long is an error ("Operation too slow"); under a
  /// limit_rate at least two of its blocks' time, so a slow limit never trips it.
  std::uint64_t stall_seconds = 20;
};

class Fetcher {
 public:
  /// Starts the fetch thread. `on_progress` is called on that thread whenever bytes arrive or it ends.
  Fetcher(std::string source, FetchOptions options, std::function<void()> on_progress);
  ~Fetcher();  ///< cancels and joins (within ~50 ms)
  Fetcher(const Fetcher&) = delete;
  Fetcher& operator=(const Fetcher&) = delete;

  /// Bytes of the pack received so far (a prefix of the file).
  std::uint64_t received() const { return received_.load(std::memory_order_acquire); }
  /// The pack's size as its manifest lays it out, once the manifest is known and accepted, else 0.
  std::uint64_t total() const { return total_.load(std::memory_order_acquire); }
  /// Header + manifest once total() > 0 (then immutable), else nullptr.
  const codec::PackInfo* info() const { return total() > 0 ? &plan_.info : nullptr; }
  /// Valid for [0, received()).
  const std::uint8_t* data() const { return buffer_.get(); }
  bool finished() const { return finished_.load(std::memory_order_acquire); }
  /// Empty while fetching and after success.
  std::string error() const;

  static bool is_url(const std::string& source);

 private:
  void run();
  void fetch_file();
  void fetch_http();
  void fail(std::string message);
  bool cancelled() const { return cancel_.load(std::memory_order_acquire); }
  /// Sleeps until `until` in slices of at most 20 ms; false if cancelled meanwhile.
  bool sleep_until(std::chrono::steady_clock::time_point until) const;
  /// Reserves plan.buffer bytes (not zero-filled), copies `head` in and publishes the manifest.
  void start_buffer(FetchPlan plan, const std::vector<std::uint8_t>& head);
  void publish(std::uint64_t received);
  /// --limit-rate: waits until `bytes` more are due since pace_start_ (false if cancelled meanwhile).
  bool pace(std::uint64_t bytes);

  std::string source_;
  FetchOptions options_;
  std::function<void()> on_progress_;
  FetchPlan plan_;                          ///< written once before total_ is published
  std::unique_ptr<std::uint8_t[]> buffer_;  ///< plan_.buffer bytes once the manifest is known
  std::atomic<std::uint64_t> received_{0}, total_{0};
  std::atomic<bool> finished_{false}, cancel_{false};
  mutable std::mutex error_mutex_;
  std::string error_;
  std::chrono::steady_clock::time_point pace_start_;  ///< fetch thread only
  std::uint64_t paced_ = 0;                           ///< bytes let in since pace_start_ (fetch thread only)
  std::thread thread_;

  friend struct FetchAccess;
};

}  // namespace geomip::viewer
