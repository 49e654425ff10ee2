// Background fetch of a .gip pack from a local file or an http:// URL, coarse → fine: the fixed header, then
// the manifest, then the chunks in file order with HTTP range requests (libcurl). The bytes arrive in one
// buffer; the received prefix is published with an atomic counter, so readers on other threads may read
// data()[0 … received()) without a lock while the fetch goes on. Errors never throw: they end the fetch and
// are reported by error().
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace geomip::viewer {

struct FetchOptions {
  std::uint64_t limit_rate = 0;      ///< bytes per second (CURLOPT_MAX_RECV_SPEED_LARGE; files: sleeps); 0 = none
  std::uint64_t request_bytes = 64 << 10;  ///< chunks are grouped into range requests of about this size
};

class Fetcher {
 public:
  /// Starts the fetch thread. `on_progress` is called on that thread whenever bytes arrive or it ends.
  Fetcher(std::string source, FetchOptions options, std::function<void()> on_progress);
  ~Fetcher();  ///< cancels and joins
  Fetcher(const Fetcher&) = delete;
  Fetcher& operator=(const Fetcher&) = delete;

  /// Bytes of the pack received so far (a prefix of the file).
  std::uint64_t received() const { return received_.load(std::memory_order_acquire); }
  /// The pack's size once the manifest is known, else 0.
  std::uint64_t total() const { return total_.load(std::memory_order_acquire); }
  /// Valid for [0, received()).
  const std::uint8_t* data() const { return buffer_.data(); }
  bool finished() const { return finished_.load(std::memory_order_acquire); }
  /// Empty while fetching and after success.
  std::string error() const;

  static bool is_url(const std::string& source);

 private:
  void run();
  void fetch_file();
  void fetch_http();
  /// One plain GET for servers that ignore Range (answer 200 with the whole file); `handle` is the CURL*.
  void fetch_http_whole(void* handle, char* curl_error);
  void fail(std::string message);
  /// Grows the buffer to `size` (only before readers may see data beyond received()).
  void publish(std::uint64_t received);

  std::string source_;
  FetchOptions options_;
  std::function<void()> on_progress_;
  std::vector<std::uint8_t> buffer_;  ///< sized to the whole pack once the manifest is known
  std::atomic<std::uint64_t> received_{0}, total_{0};
  std::atomic<bool> finished_{false}, cancel_{false};
  mutable std::mutex error_mutex_;
  std::string error_;
  std::thread thread_;

  friend struct FetchAccess;
};

}  // namespace geomip::viewer
