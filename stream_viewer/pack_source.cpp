#include "stream_viewer/pack_source.h"

#include <time.h>

#include <algorithm>
#include <chrono>

namespace geomip::viewer {
namespace {

/// CPU time of the calling thread, milliseconds (POSIX CLOCK_THREAD_CPUTIME_ID).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) / 1e6;
}

}  // namespace

PackSource::PackSource(const std::string& source, FetchOptions fetch, morph::DecodeSettings decode)
    : decode_(decode) {
  fetcher_ = std::make_unique<Fetcher>(source, fetch, [this] { wake_.notify_all(); });
  decoder_ = std::thread([this] { decode_loop(); });
}

PackSource::~PackSource() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  decoder_.join();   // may finish a decode in progress first
  fetcher_.reset();  // cancels and joins the fetch
}

std::optional<SourceUpdate> PackSource::take_update() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<SourceUpdate> u = std::move(pending_);
  pending_.reset();
  return u;
}

PackSource::DecodeStats PackSource::decode_stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return decode_stats_;
}

bool PackSource::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return decoder_idle_ && !pending_;
}

std::string PackSource::error() const {
  std::string e = fetcher_->error();
  std::lock_guard<std::mutex> lock(mutex_);
  return e.empty() ? decode_error_ : e;
}

bool PackSource::complete() const {
  if (!fetcher_->finished() || !error().empty()) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  return decoded_end_ == fetcher_->total() && fetcher_->total() > 0;
}

void PackSource::decode_loop() {
  try {
    decode_chunks();
  } catch (const std::exception& e) {  // nothing leaves this thread: the error is reported by error()
    std::lock_guard<std::mutex> lock(mutex_);
    if (decode_error_.empty()) decode_error_ = std::string("decode failed: ") + e.what();
  }
  // Idle for good once the fetch has ended (done() then becomes true).
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_ && !fetcher_->finished()) wake_.wait_for(lock, std::chrono::milliseconds(50));
  decoder_idle_ = true;
}

void PackSource::decode_chunks() {
  const codec::PackInfo* info = nullptr;  // the fetcher's, checked against the source's size
  std::size_t next_chunk = 0;             // first chunk not yet complete
  morph::SceneDecoder scene(decode_);     // decodes each chunk once, however many updates there are
  for (;;) {
    std::uint64_t end = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      for (;;) {
        if (stop_) return;
        const bool finished = fetcher_->finished();
        const std::uint64_t received = fetcher_->received();
        if (!info) info = fetcher_->info();
        std::size_t c = next_chunk;
        while (info && c < info->chunks.size() && info->chunks[c].offset + info->chunks[c].size <= received)
          ++c;
        if (info && c > next_chunk && decode_error_.empty()) {
          next_chunk = c;
          end = info->chunks[c - 1].offset + info->chunks[c - 1].size;
          decoder_idle_ = false;
          break;
        }
        if (finished) {
          decoder_idle_ = true;
          return;
        }
        wake_.wait_for(lock, std::chrono::milliseconds(50));
      }
    }
    codec::Status status = codec::Status::kOk;
    std::size_t used = 0;
    std::vector<morph::SceneModel> models;
    std::string err;
    try {
      const auto t0 = std::chrono::steady_clock::now();
      const double cpu0 = thread_cpu_ms();
      models = scene.update({fetcher_->data(), static_cast<std::size_t>(end)}, status, used);
      const double cpu = thread_cpu_ms() - cpu0;
      const double wall =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::lock_guard<std::mutex> lock(mutex_);
      decode_stats_.updates += 1;
      decode_stats_.thread_cpu_ms += cpu;
      decode_stats_.wall_ms += wall;
    } catch (const std::exception& e) {
      err = std::string("decode failed: ") + e.what();
    }
    if (status == codec::Status::kCorrupt || status == codec::Status::kUnsupportedVersion)
      err = "decode stopped at byte " + std::to_string(used) + ": " +
            std::string(codec::status_message(status));
    std::lock_guard<std::mutex> lock(mutex_);
    if (!err.empty() && decode_error_.empty()) decode_error_ = err;  // later chunks are not decoded
    decoded_end_ = end;
    // bytes_used: what the shown models really come from (less than `end` when a chunk failed its CRC)
    if (!models.empty())
      pending_ = SourceUpdate{std::move(models), std::min<std::uint64_t>(used, end), fetcher_->total()};
  }
}

}  // namespace geomip::viewer
