#include "stream_viewer/fetcher.h"

#include <curl/curl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "codec/pack.h"

namespace geomip::viewer {

struct FetchAccess {
  // Range request state for the curl write callback.
  struct Range {
    Fetcher* self;
    std::uint64_t begin, end, at;  // [begin, end) wanted; `at` = next byte to write
    std::vector<std::uint8_t>* header;  // small reads before the buffer is sized
  };

  static std::size_t write(char* ptr, std::size_t size, std::size_t nmemb, void* user) {
    auto* r = static_cast<Range*>(user);
    const std::size_t n = size * nmemb;
    if (r->self->cancel_.load()) return 0;  // aborts the transfer
    if (r->at >= r->end) return 0;  // more than asked: the server ignores Range (see fetch_http_whole)
    const std::uint64_t room = r->end - r->at;
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(room, n));
    if (r->header) {
      r->header->insert(r->header->end(), ptr, ptr + take);
    } else {
      std::memcpy(r->self->buffer_.data() + r->at, ptr, take);
      r->self->publish(r->at + take);
    }
    r->at += take;
    return take == n ? n : 0;
  }

  // Whole-file GET for servers without Range support: header and manifest first, then the buffer is sized
  // and the rest streams into it, published as it comes.
  struct Whole {
    Fetcher* self;
    std::vector<std::uint8_t> head;
    std::size_t manifest_end = 0;
    std::uint64_t at = 0, total = 0;
    std::string error;
  };

  static std::size_t write_whole(char* ptr, std::size_t size, std::size_t nmemb, void* user) {
    auto* w = static_cast<Whole*>(user);
    const std::size_t n = size * nmemb;
    if (w->self->cancel_.load()) return 0;
    if (w->total == 0) {
      w->head.insert(w->head.end(), ptr, ptr + n);
      if (w->manifest_end == 0 && w->head.size() >= codec::kPackHeaderSize) {
        const codec::Status st = codec::read_pack_header(w->head, w->manifest_end);
        if (st != codec::Status::kOk) {
          w->error = "not a .gip pack (" + std::string(codec::status_message(st)) + ")";
          return 0;
        }
      }
      if (w->manifest_end == 0 || w->head.size() < w->manifest_end) return n;
      codec::PackInfo info;
      const codec::Status st = codec::read_pack_info(w->head, info);
      if (st != codec::Status::kOk) {
        w->error = "not a readable .gip pack (manifest: " + std::string(codec::status_message(st)) + ")";
        return 0;
      }
      w->total = std::max<std::uint64_t>(info.file_size(), w->manifest_end);
      w->self->buffer_.assign(w->total, 0);
      w->at = std::min<std::uint64_t>(w->head.size(), w->total);
      std::copy(w->head.begin(), w->head.begin() + static_cast<std::ptrdiff_t>(w->at), w->self->buffer_.begin());
      w->self->total_.store(w->total, std::memory_order_release);
      w->self->publish(w->at);
      return n;
    }
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(w->total - w->at, n));
    std::memcpy(w->self->buffer_.data() + w->at, ptr, take);
    w->at += take;
    w->self->publish(w->at);
    return n;
  }

  // Called by libcurl often, also while no byte arrives: lets the destructor cancel a stalled transfer.
  static int progress(void* user, curl_off_t, curl_off_t, curl_off_t, curl_off_t) {
    return static_cast<Fetcher*>(user)->cancel_.load() ? 1 : 0;
  }
};

namespace {

std::string status_text(long code) {
  switch (code) {
    case 404: return "404 Not Found";
    case 403: return "403 Forbidden";
    case 416: return "416 Range Not Satisfiable";
    case 500: return "500 Internal Server Error";
    default: return std::to_string(code);
  }
}

}  // namespace

bool Fetcher::is_url(const std::string& source) {
  return source.rfind("http://", 0) == 0 || source.rfind("https://", 0) == 0;
}

Fetcher::Fetcher(std::string source, FetchOptions options, std::function<void()> on_progress)
    : source_(std::move(source)), options_(options), on_progress_(std::move(on_progress)) {
  thread_ = std::thread([this] { run(); });
}

Fetcher::~Fetcher() {
  cancel_ = true;
  if (thread_.joinable()) thread_.join();
}

std::string Fetcher::error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return error_;
}

void Fetcher::fail(std::string message) {
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    if (error_.empty()) error_ = std::move(message);
  }
}

void Fetcher::publish(std::uint64_t received) {
  received_.store(received, std::memory_order_release);
  if (on_progress_) on_progress_();
}

void Fetcher::run() {
  if (is_url(source_))
    fetch_http();
  else
    fetch_file();
  finished_.store(true, std::memory_order_release);
  if (on_progress_) on_progress_();
}

// Validates header + manifest in `head` and sizes the buffer. Returns false (with the error set) on failure.
static bool size_from_manifest(const std::vector<std::uint8_t>& head, codec::PackInfo& info, std::string& error) {
  const codec::Status st = codec::read_pack_info(head, info);
  if (st != codec::Status::kOk) {
    error = "not a readable .gip pack (manifest: " + std::string(codec::status_message(st)) + ")";
    return false;
  }
  return true;
}

void Fetcher::fetch_file() {
  std::ifstream in(source_, std::ios::binary);
  if (!in) return fail("cannot open " + source_);
  in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  std::vector<std::uint8_t> head(std::min<std::uint64_t>(size, codec::kPackHeaderSize));
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  std::size_t manifest_end = 0;
  const codec::Status st = codec::read_pack_header(head, manifest_end);
  if (st != codec::Status::kOk)
    return fail(source_ + ": not a .gip pack (" + std::string(codec::status_message(st)) + ")");
  if (manifest_end > size) return fail(source_ + ": truncated .gip pack (manifest ends past the file)");
  head.resize(manifest_end);
  in.read(reinterpret_cast<char*>(head.data() + codec::kPackHeaderSize),
          static_cast<std::streamsize>(manifest_end - codec::kPackHeaderSize));
  codec::PackInfo info;
  std::string err;
  if (!size_from_manifest(head, info, err)) return fail(source_ + ": " + err);
  const std::uint64_t total = std::max<std::uint64_t>(info.file_size(), manifest_end);
  buffer_.assign(total, 0);
  std::copy(head.begin(), head.end(), buffer_.begin());
  total_.store(total, std::memory_order_release);
  publish(manifest_end);
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t at = manifest_end;
  const std::uint64_t end = std::min(total, size);
  while (at < end && !cancel_) {
    const std::uint64_t n = std::min<std::uint64_t>(end - at, 16 << 10);
    in.read(reinterpret_cast<char*>(buffer_.data() + at), static_cast<std::streamsize>(n));
    if (!in) return fail(source_ + ": read error");
    at += n;
    if (options_.limit_rate > 0) {
      const double due = static_cast<double>(at - manifest_end) / static_cast<double>(options_.limit_rate);
      std::this_thread::sleep_until(start + std::chrono::duration<double>(due));
    }
    publish(at);
  }
  if (size < total) fail(source_ + ": truncated .gip pack (" + std::to_string(size) + " of " +
                         std::to_string(total) + " bytes)");
}

void Fetcher::fetch_http() {
  static const bool curl_ready = curl_global_init(CURL_GLOBAL_DEFAULT) == CURLE_OK;
  if (!curl_ready) return fail("libcurl initialisation failed");
  CURL* curl = curl_easy_init();
  if (!curl) return fail("libcurl initialisation failed");
  char curl_error[CURL_ERROR_SIZE] = {0};
  curl_easy_setopt(curl, CURLOPT_URL, source_.c_str());
  curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, &FetchAccess::write);
  curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, curl_error);
  curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(curl, CURLOPT_NOPROGRESS, 0L);
  curl_easy_setopt(curl, CURLOPT_XFERINFOFUNCTION, &FetchAccess::progress);
  curl_easy_setopt(curl, CURLOPT_XFERINFODATA, this);
  curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT, 10L);
  curl_easy_setopt(curl, CURLOPT_LOW_SPEED_LIMIT, 1L);   // a stalled connection is an error after 20 s
  curl_easy_setopt(curl, CURLOPT_LOW_SPEED_TIME, 20L);
  if (options_.limit_rate > 0)
    curl_easy_setopt(curl, CURLOPT_MAX_RECV_SPEED_LARGE, static_cast<curl_off_t>(options_.limit_rate));

  bool no_ranges = false;
  // One range request [begin, end) → buffer (or `header`). Returns false with the error set (or no_ranges).
  auto request = [&](std::uint64_t begin, std::uint64_t end, std::vector<std::uint8_t>* header) -> bool {
    FetchAccess::Range r{this, begin, end, begin, header};
    const std::string range = std::to_string(begin) + "-" + std::to_string(end - 1);
    curl_easy_setopt(curl, CURLOPT_RANGE, range.c_str());
    curl_easy_setopt(curl, CURLOPT_WRITEDATA, &r);
    curl_error[0] = 0;
    const CURLcode rc = curl_easy_perform(curl);
    long code = 0;
    curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &code);
    if (cancel_) return false;
    if (code >= 400) {
      fail(source_ + ": HTTP " + status_text(code));
      return false;
    }
    if (code == 200 && begin == 0 && header) {
      no_ranges = true;  // the server sends the whole file: fetch it in one GET instead
      return false;
    }
    if (rc != CURLE_OK) {
      fail(source_ + ": connection failed after " + std::to_string(r.at) + " bytes: " +
           (curl_error[0] ? curl_error : curl_easy_strerror(rc)));
      return false;
    }
    if (code != 206) {
      fail(source_ + ": server does not answer range requests (HTTP " + std::to_string(code) + ")");
      return false;
    }
    if (r.at < end) {
      fail(source_ + ": connection closed after " + std::to_string(r.at) + " of " + std::to_string(end) +
           " bytes");
      return false;
    }
    return true;
  };

  std::vector<std::uint8_t> head;
  std::size_t manifest_end = 0;
  codec::PackInfo info;
  std::string err;
  bool ok = request(0, codec::kPackHeaderSize, &head);
  if (no_ranges) {
    fetch_http_whole(curl, curl_error);
    curl_easy_cleanup(curl);
    return;
  }
  if (ok) {
    const codec::Status st = codec::read_pack_header(head, manifest_end);
    if (st != codec::Status::kOk) {
      fail(source_ + ": not a .gip pack (" + std::string(codec::status_message(st)) + ")");
      ok = false;
    }
  }
  if (ok) ok = request(codec::kPackHeaderSize, manifest_end, &head);
  if (ok && !size_from_manifest(head, info, err)) {
    fail(source_ + ": " + err);
    ok = false;
  }
  if (ok) {
    const std::uint64_t total = std::max<std::uint64_t>(info.file_size(), manifest_end);
    buffer_.assign(total, 0);
    std::copy(head.begin(), head.end(), buffer_.begin());
    total_.store(total, std::memory_order_release);
    publish(manifest_end);
    // Chunks in file order, grouped into requests of about request_bytes.
    std::size_t c = 0;
    while (ok && c < info.chunks.size() && !cancel_) {
      const std::uint64_t begin = info.chunks[c].offset;
      std::uint64_t end = begin + info.chunks[c].size;
      ++c;
      while (c < info.chunks.size() && end - begin < options_.request_bytes) end += info.chunks[c++].size;
      if (end > begin) ok = request(begin, end, nullptr);
    }
  }
  curl_easy_cleanup(curl);
}

void Fetcher::fetch_http_whole(void* handle, char* curl_error) {
  CURL* curl = static_cast<CURL*>(handle);
  FetchAccess::Whole w{this, {}, 0, 0, 0, {}};
  curl_easy_setopt(curl, CURLOPT_RANGE, nullptr);
  curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, &FetchAccess::write_whole);
  curl_easy_setopt(curl, CURLOPT_WRITEDATA, &w);
  curl_error[0] = 0;
  const CURLcode rc = curl_easy_perform(curl);
  long code = 0;
  curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &code);
  if (cancel_) return;
  if (!w.error.empty()) return fail(source_ + ": " + w.error);
  if (code >= 400) return fail(source_ + ": HTTP " + status_text(code));
  if (rc != CURLE_OK)
    return fail(source_ + ": connection failed after " + std::to_string(w.at) + " bytes: " +
                (curl_error[0] ? curl_error : curl_easy_strerror(rc)));
  if (w.total == 0) return fail(source_ + ": not a .gip pack (too short)");
  if (w.at < w.total)
    fail(source_ + ": connection closed after " + std::to_string(w.at) + " of " + std::to_string(w.total) +
         " bytes");
}

}  // namespace geomip::viewer
