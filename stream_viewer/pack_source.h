// The viewer's glue to the codec: a pack from a file or URL, fetched in the background (fetcher.h) and
// decoded on a worker thread each time new complete chunks arrive — incrementally (morph::SceneDecoder), so
// each byte is decoded once however many updates the stream brings; the render thread polls take_update(),
// which never blocks on the network or the decoder.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "codec/pack.h"
#include "morph/scene_model.h"
#include "stream_viewer/fetcher.h"

namespace geomip::viewer {

struct SourceUpdate {
  std::vector<morph::SceneModel> models;
  std::uint64_t bytes_used = 0;  ///< bytes of the pack those models come from (complete chunks)
  std::uint64_t total = 0;       ///< the pack's size
};

class PackSource {
 public:
  PackSource(const std::string& source, FetchOptions fetch, morph::DecodeSettings decode);
  ~PackSource();
  PackSource(const PackSource&) = delete;
  PackSource& operator=(const PackSource&) = delete;

  /// The newest decoded models, once per decode; std::nullopt if nothing new.
  std::optional<SourceUpdate> take_update();

  std::uint64_t received() const { return fetcher_->received(); }
  std::uint64_t total() const { return fetcher_->total(); }
  /// Header + manifest once the fetch accepted them (then immutable), else nullptr.
  const codec::PackInfo* info() const { return fetcher_->info(); }
  /// Fetch ended (complete or failed) and every byte that arrived has been decoded and taken or queued.
  bool done() const;
  /// Fetch or decode error, empty if none.
  std::string error() const;
  /// Whole pack received and decoded without error.
  bool complete() const;

  /// What decoding cost so far: scene updates (each decodes only the chunks that completed since the last
  /// one: morph::SceneDecoder), the decode thread's CPU time in them (the per-patch worker threads a decode
  /// starts are not counted) and their wall time.
  struct DecodeStats {
    int updates = 0;
    double thread_cpu_ms = 0;
    double wall_ms = 0;
  };
  DecodeStats decode_stats() const;

 private:
  void decode_loop();
  void decode_chunks();  ///< the decode loop proper; may throw (decode_loop turns that into error())

  morph::DecodeSettings decode_;
  std::unique_ptr<Fetcher> fetcher_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool decoder_idle_ = false;
  std::optional<SourceUpdate> pending_;
  std::string decode_error_;
  std::uint64_t decoded_end_ = 0;
  DecodeStats decode_stats_;
  std::thread decoder_;
};

}  // namespace geomip::viewer
