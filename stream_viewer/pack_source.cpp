#include "stream_viewer/pack_source.h"

#include <algorithm>

namespace geomip::viewer {

PackSource::PackSource(const std::string& source, FetchOptions fetch, morph::DecodeSettings decode) : decode_(decode) {
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
  codec::PackInfo info;
  bool have_info = false;
  std::size_t next_chunk = 0;  // first chunk not yet complete
  for (;;) {
    std::uint64_t end = 0;
    bool finished = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      for (;;) {
        if (stop_) return;
        finished = fetcher_->finished();
        const std::uint64_t received = fetcher_->received();
        const std::uint64_t total = fetcher_->total();
        if (!have_info && total > 0) {
          // the manifest arrived: the chunk table tells where complete chunks end
          lock.unlock();
          have_info = codec::read_pack_info({fetcher_->data(), static_cast<std::size_t>(received)}, info) ==
                      codec::Status::kOk;
          lock.lock();
        }
        std::size_t c = next_chunk;
        while (have_info && c < info.chunks.size() && info.chunks[c].offset + info.chunks[c].size <= received) ++c;
        if (have_info && c > next_chunk) {
          next_chunk = c;
          end = info.chunks[c - 1].offset + info.chunks[c - 1].size;
          decoder_idle_ = false;
          break;
        }
        if (finished) {
          decoder_idle_ = true;
          if (stop_) return;
        }
        wake_.wait_for(lock, std::chrono::milliseconds(50));
      }
    }
    codec::Status status = codec::Status::kOk;
    std::size_t used = 0;
    std::vector<morph::SceneModel> models;
    std::string err;
    try {
      models = morph::decode_scene({fetcher_->data(), static_cast<std::size_t>(end)}, decode_, status, used);
    } catch (const std::exception& e) {
      err = std::string("decode failed: ") + e.what();
    }
    if (status == codec::Status::kCorrupt || status == codec::Status::kUnsupportedVersion)
      err = "decode: " + std::string(codec::status_message(status));
    std::lock_guard<std::mutex> lock(mutex_);
    if (!err.empty() && decode_error_.empty()) decode_error_ = err;
    decoded_end_ = end;
    if (!models.empty()) pending_ = SourceUpdate{std::move(models), end, fetcher_->total()};
  }
}

}  // namespace geomip::viewer
