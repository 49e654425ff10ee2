#include "stream_viewer/fetcher.h"

#include <curl/curl.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>

#include <strings.h>

namespace geomip::viewer {

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

// "bytes A-B/N" → A and N (N = kUnknownSize for "*"); false if not of that form.
bool parse_content_range(const std::string& value, std::uint64_t& first, std::uint64_t& total) {
  unsigned long long a = 0, b = 0, n = 0;
  if (std::sscanf(value.c_str(), " bytes %llu-%llu/%llu", &a, &b, &n) == 3) {
    first = a, total = n;
    return true;
  }
  if (std::sscanf(value.c_str(), " bytes %llu-%llu/*", &a, &b) == 2) {
    first = a, total = kUnknownSize;
    return true;
  }
  return false;
}

}  // namespace

// The state of one HTTP request, shared with libcurl's callbacks.
struct FetchAccess {
  struct Transfer {
    Fetcher* self = nullptr;
    CURL* curl = nullptr;
    std::uint64_t begin = 0, end = 0, at = 0;       // [begin, end) wanted; `at` = next byte to write
    std::vector<std::uint8_t>* head = nullptr;      // small reads before the buffer exists
    bool allow_whole = false;  // a 200 (Range ignored) is welcome: the first request, begin = 0
    bool started = false, whole = false, done = false;
    long code = 0;
    std::uint64_t range_first = kUnknownSize, range_total = kUnknownSize;  // from Content-Range
    std::size_t manifest_end = 0;  // whole mode: from the header
    std::string error;  // set by a callback that stopped the transfer on purpose
  };

  static std::size_t header_line(Transfer* t, const char* ptr, std::size_t n) {
    if (n > 4096) return n;  // no header the fetch reads is that long
    const std::string line(ptr, n);
    if (line.rfind("HTTP/", 0) == 0) {  // a new response (after a redirect): forget the previous one's fields
      t->range_first = t->range_total = kUnknownSize;
    } else if (line.size() > 14 && strncasecmp(line.c_str(), "content-range:", 14) == 0) {
      if (!parse_content_range(line.substr(14), t->range_first, t->range_total))
        t->range_first = t->range_total = kUnknownSize;
    }
    return n;
  }

  // Cuts the transfer (libcurl then reports a write error, which request() ignores when `done`).
  static std::size_t stop(Transfer* t, std::string error) {
    t->error = std::move(error);
    return 0;
  }

  static std::size_t write_body(Transfer* t, char* ptr, std::size_t n) {
    Fetcher* self = t->self;
    if (self->cancelled()) return 0;
    if (!t->started) {
      t->started = true;
      curl_easy_getinfo(t->curl, CURLINFO_RESPONSE_CODE, &t->code);
      if (t->code >= 300) return 0;  // an error page: request() reports the status, its body is not wanted
      if (t->code == 200) {
        if (!t->allow_whole) return stop(t, "server stopped answering range requests");
        t->whole = true;  // the server ignores Range and sends the whole file: read it from this one GET
      } else if (t->code == 206) {
        if (t->range_first != kUnknownSize && t->range_first != t->begin)
          return stop(t, "server sent bytes from " + std::to_string(t->range_first) + ", asked for " +
                             std::to_string(t->begin));
      } else {
        return stop(t, "unexpected HTTP " + std::to_string(t->code));
      }
    }
    return t->whole ? write_whole(t, ptr, n) : write_range(t, ptr, n);
  }

  // libcurl's callbacks: no exception may unwind through libcurl (a C library).
  static std::size_t write(char* ptr, std::size_t size, std::size_t nmemb, void* user) noexcept {
    auto* t = static_cast<Transfer*>(user);
    const std::size_t n = size * nmemb;
    try {
      const std::uint64_t rate = t->self->options_.limit_rate;
      if (rate == 0) return write_body(t, ptr, n);
      // --limit-rate: let the bytes in block by block at the rate (waiting here, cancellable)
      for (std::size_t used = 0; used < n;) {
        const std::size_t piece =
            static_cast<std::size_t>(std::min<std::uint64_t>(n - used, rate_block(rate)));
        if (!t->self->pace(piece)) return 0;
        if (write_body(t, ptr + used, piece) != piece) return 0;  // cut or stopped: as for the whole write
        used += piece;
      }
      return n;
    } catch (...) {
      try {  // std::bad_alloc is the only exception write_body can throw
        t->error = "out of memory while fetching";
      } catch (...) {  // then request() reports the write error libcurl returns
      }
      return 0;
    }
  }
  static std::size_t header(char* ptr, std::size_t size, std::size_t nmemb, void* user) noexcept {
    try {
      return header_line(static_cast<Transfer*>(user), ptr, size * nmemb);
    } catch (...) {
      return 0;
    }
  }

  static std::size_t write_range(Transfer* t, const char* ptr, std::size_t n) {
    const std::uint64_t room = t->end - t->at;
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(room, n));
    if (t->head) {
      t->head->insert(t->head->end(), ptr, ptr + take);
    } else {
      std::memcpy(t->self->buffer_.get() + t->at, ptr, take);
      t->self->publish(t->at + take);
    }
    t->at += take;
    t->done = t->at == t->end;
    return take == n ? n : 0;  // a body longer than the range asked for is cut there
  }

  // Whole-file GET: header and manifest into `head`, then the buffer is planned against the Content-Length
  // and the rest streams into it, published as it comes; anything past the planned size is cut.
  static std::size_t write_whole(Transfer* t, const char* ptr, std::size_t n) {
    Fetcher* self = t->self;
    std::size_t used = 0;
    if (!self->buffer_) {
      std::vector<std::uint8_t>& head = *t->head;
      curl_off_t length = -1;
      curl_easy_getinfo(t->curl, CURLINFO_CONTENT_LENGTH_DOWNLOAD_T, &length);
      const std::uint64_t available = length >= 0 ? static_cast<std::uint64_t>(length) : kUnknownSize;
      // never more into `head` than the header, then than the manifest
      const std::size_t want = t->manifest_end ? t->manifest_end : codec::kPackHeaderSize;
      used = std::min(n, want - head.size());
      head.insert(head.end(), ptr, ptr + used);
      t->at = head.size();  // for the messages
      if (head.size() < want) return n;
      if (t->manifest_end == 0) {
        if (std::string e = check_pack_header(head, available, t->manifest_end); !e.empty()) return stop(t, e);
        if (head.size() < t->manifest_end) {
          const std::size_t more = std::min(n - used, t->manifest_end - head.size());
          head.insert(head.end(), ptr + used, ptr + used + more);
          used += more;
          t->at = head.size();
          if (head.size() < t->manifest_end) return n;
        }
      }
      FetchPlan plan;
      if (std::string e = plan_fetch(head, available, plan); !e.empty()) return stop(t, e);
      self->start_buffer(std::move(plan), head);
      t->at = t->manifest_end;
      t->end = self->plan_.buffer;
      t->head = nullptr;
      t->done = t->at == t->end;  // a pack without chunks
      if (used == n) return n;
    }
    const std::uint64_t room = t->end - t->at;
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(room, n - used));
    std::memcpy(self->buffer_.get() + t->at, ptr + used, take);
    t->at += take;
    self->publish(t->at);
    t->done = t->at == t->end;
    return used + take == n ? n : 0;  // an endless body is cut at the planned size
  }
};

bool Fetcher::is_url(const std::string& source) {
  return source.rfind("http://", 0) == 0 || source.rfind("https://", 0) == 0;
}

Fetcher::Fetcher(std::string source, FetchOptions options, std::function<void()> on_progress)
    : source_(std::move(source)), options_(options), on_progress_(std::move(on_progress)) {
  thread_ = std::thread([this] { run(); });
}

Fetcher::~Fetcher() {
  cancel_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

std::string Fetcher::error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return error_;
}

void Fetcher::fail(std::string message) {
  std::lock_guard<std::mutex> lock(error_mutex_);
  if (error_.empty()) error_ = std::move(message);
}

void Fetcher::publish(std::uint64_t received) {
  received_.store(received, std::memory_order_release);
  if (on_progress_) on_progress_();
}

bool Fetcher::pace(std::uint64_t bytes) {
  paced_ += bytes;
  const double due = static_cast<double>(paced_) / static_cast<double>(options_.limit_rate);
  return sleep_until(pace_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                       std::chrono::duration<double>(due)));
}

bool Fetcher::sleep_until(std::chrono::steady_clock::time_point until) const {
  for (;;) {
    if (cancelled()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now >= until) return true;
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(until - now,
                                                                              std::chrono::milliseconds(20)));
  }
}

void Fetcher::start_buffer(FetchPlan plan, const std::vector<std::uint8_t>& head) {
  plan_ = std::move(plan);
  // Not zero-filled: pages are touched only as bytes arrive. plan_.buffer ≤ the source's size and kMaxPackBytes.
  buffer_ = std::make_unique_for_overwrite<std::uint8_t[]>(static_cast<std::size_t>(plan_.buffer));
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(head.size(), plan_.buffer));
  std::copy(head.begin(), head.begin() + static_cast<std::ptrdiff_t>(n), buffer_.get());
  total_.store(plan_.total, std::memory_order_release);
  publish(n);
}

void Fetcher::run() {
  try {
    if (is_url(source_))
      fetch_http();
    else
      fetch_file();
  } catch (const std::bad_alloc&) {
    fail(source_ + ": out of memory while fetching");
  } catch (const std::exception& e) {
    fail(source_ + ": fetch failed: " + e.what());
  } catch (...) {
    fail(source_ + ": fetch failed");
  }
  finished_.store(true, std::memory_order_release);
  if (on_progress_) on_progress_();
}

void Fetcher::fetch_file() {
  std::ifstream in(source_, std::ios::binary);
  if (!in) return fail("cannot open " + source_);
  in.seekg(0, std::ios::end);
  const std::streamoff end_pos = in.tellg();
  if (end_pos < 0) return fail("cannot read " + source_);
  const std::uint64_t size = static_cast<std::uint64_t>(end_pos);
  in.seekg(0);
  std::vector<std::uint8_t> head(static_cast<std::size_t>(std::min<std::uint64_t>(size, codec::kPackHeaderSize)));
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  if (!in) return fail("cannot read " + source_);
  std::size_t manifest_end = 0;
  if (std::string e = check_pack_header(head, size, manifest_end); !e.empty()) return fail(source_ + ": " + e);
  head.resize(manifest_end);  // ≤ the file's size (checked)
  in.read(reinterpret_cast<char*>(head.data() + codec::kPackHeaderSize),
          static_cast<std::streamsize>(manifest_end - codec::kPackHeaderSize));
  if (!in) return fail(source_ + ": read error");
  FetchPlan plan;
  if (std::string e = plan_fetch(head, size, plan); !e.empty()) return fail(source_ + ": " + e);
  start_buffer(std::move(plan), head);
  const std::uint64_t end = plan_.buffer;
  // Rate-limited reads come in blocks of ~1/10 s of the rate, so progress (and cancelling) stays smooth.
  const std::uint64_t block = options_.limit_rate > 0 ? rate_block(options_.limit_rate) : 16 << 10;
  pace_start_ = std::chrono::steady_clock::now();
  std::uint64_t at = manifest_end;
  while (at < end) {
    if (cancelled()) return;
    const std::uint64_t n = std::min<std::uint64_t>(end - at, block);
    in.read(reinterpret_cast<char*>(buffer_.get() + at), static_cast<std::streamsize>(n));
    if (!in) return fail(source_ + ": read error after " + std::to_string(at) + " bytes");
    at += n;
    if (options_.limit_rate > 0 && !pace(n)) return;
    publish(at);
  }
  if (plan_.truncated())
    fail(source_ + ": truncated .gip pack (" + std::to_string(size) + " of " + std::to_string(plan_.total) +
         " bytes)");
}

void Fetcher::fetch_http() {
  static const bool curl_ready = curl_global_init(CURL_GLOBAL_DEFAULT) == CURLE_OK;
  if (!curl_ready) return fail("libcurl initialisation failed");
  std::unique_ptr<CURL, void (*)(CURL*)> easy(curl_easy_init(), curl_easy_cleanup);
  std::unique_ptr<CURLM, CURLMcode (*)(CURLM*)> multi(curl_multi_init(), curl_multi_cleanup);
  if (!easy || !multi) return fail("libcurl initialisation failed");
  CURL* curl = easy.get();
  char curl_error[CURL_ERROR_SIZE] = {0};
  curl_easy_setopt(curl, CURLOPT_URL, source_.c_str());
  curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, &FetchAccess::write);
  curl_easy_setopt(curl, CURLOPT_HEADERFUNCTION, &FetchAccess::header);
  curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, curl_error);
  curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(curl, CURLOPT_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(curl, CURLOPT_FOLLOWLOCATION, 1L);
  curl_easy_setopt(curl, CURLOPT_MAXREDIRS, kMaxRedirects);
  curl_easy_setopt(curl, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT, 10L);
  // --limit-rate is paced in the write callback (write()), not with CURLOPT_MAX_RECV_SPEED_LARGE: libcurl
  // 7.88 evens out the rate per transfer after the fact, so a 64 KiB range request came in at once (the bunny
  // at 10,000 bytes/s in 1 s), and at 1000 bytes/s the wait after ~36 KiB tripped the stall guard (exit 3).
  std::uint64_t stall_seconds = std::max<std::uint64_t>(options_.stall_seconds, 1);
  if (options_.limit_rate > 0)
    stall_seconds = std::max(stall_seconds, 2 * rate_block(options_.limit_rate) / options_.limit_rate + 1);
  pace_start_ = std::chrono::steady_clock::now();
  curl_easy_setopt(curl, CURLOPT_LOW_SPEED_LIMIT, 1L);  // a stalled connection is an error
  curl_easy_setopt(curl, CURLOPT_LOW_SPEED_TIME,
                   static_cast<long>(std::min<std::uint64_t>(stall_seconds, 1 << 30)));

  // Runs one transfer on the multi handle, polling at most 50 ms at a time so cancel_ is seen promptly
  // (also on a stalled server; --limit-rate waits in write() check it themselves).
  auto perform = [&]() -> CURLcode {
    curl_multi_add_handle(multi.get(), curl);
    CURLcode result = CURLE_ABORTED_BY_CALLBACK;
    int running = 1;
    while (running && !cancelled()) {
      if (curl_multi_perform(multi.get(), &running) != CURLM_OK) break;
      if (running) curl_multi_poll(multi.get(), nullptr, 0, 50, nullptr);
    }
    int left = 0;
    while (CURLMsg* m = curl_multi_info_read(multi.get(), &left))
      if (m->msg == CURLMSG_DONE && m->easy_handle == curl) result = m->data.result;
    curl_multi_remove_handle(multi.get(), curl);
    return result;
  };

  // One request for [begin, end) (into `head` before the buffer exists). Returns false with the error set.
  auto request = [&](FetchAccess::Transfer& t) -> bool {
    t.self = this;
    t.curl = curl;
    t.at = t.begin;
    const std::string range = std::to_string(t.begin) + "-" + std::to_string(t.end - 1);
    curl_easy_setopt(curl, CURLOPT_RANGE, range.c_str());
    curl_easy_setopt(curl, CURLOPT_WRITEDATA, &t);
    curl_easy_setopt(curl, CURLOPT_HEADERDATA, &t);
    curl_error[0] = 0;
    const CURLcode rc = perform();
    if (cancelled()) return false;
    curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &t.code);
    if (!t.error.empty()) {
      fail(source_ + ": " + t.error);
      return false;
    }
    if (t.code >= 400) {
      fail(source_ + ": HTTP " + status_text(t.code));
      return false;
    }
    if (t.done) return true;  // everything wanted arrived (a longer body was cut on purpose)
    if (rc == CURLE_TOO_MANY_REDIRECTS) {
      fail(source_ + ": more than " + std::to_string(kMaxRedirects) + " redirects");
      return false;
    }
    if (t.code >= 300) {
      fail(source_ + ": HTTP " + status_text(t.code) + " (a redirect that could not be followed)");
      return false;
    }
    if (rc != CURLE_OK) {
      fail(source_ + ": connection failed after " + std::to_string(t.at) + " bytes: " +
           (curl_error[0] ? curl_error : curl_easy_strerror(rc)));
      return false;
    }
    if ((t.whole && !buffer_) || (t.begin == 0 && t.range_total != kUnknownSize && t.range_total < t.end)) {
      fail(source_ + ": not a .gip pack (too short: " + std::to_string(t.at) + " bytes)");
      return false;
    }
    fail(source_ + ": connection closed after " + std::to_string(t.at) + " of " + std::to_string(t.end) + " bytes");
    return false;
  };

  std::vector<std::uint8_t> head;
  FetchAccess::Transfer first;
  first.begin = 0;
  first.end = codec::kPackHeaderSize;
  first.head = &head;
  first.allow_whole = true;
  if (!request(first)) {
    // A server that ignores Range may have sent less than the header: still a clear "not a pack".
    return;
  }
  // Later requests go straight to where the redirects (if any) led.
  char* effective = nullptr;
  std::string effective_url;
  if (curl_easy_getinfo(curl, CURLINFO_EFFECTIVE_URL, &effective) == CURLE_OK && effective)
    effective_url = effective;
  if (!effective_url.empty()) curl_easy_setopt(curl, CURLOPT_URL, effective_url.c_str());
  if (first.whole) {  // the one GET already read the whole pack
    if (plan_.truncated())
      fail(source_ + ": truncated .gip pack (the server sent " + std::to_string(plan_.buffer) + " of " +
           std::to_string(plan_.total) + " bytes)");
    return;
  }
  const std::uint64_t available = first.range_total;  // the Content-Range total, kUnknownSize if not sent
  std::size_t manifest_end = 0;
  if (std::string e = check_pack_header(head, available, manifest_end); !e.empty()) return fail(source_ + ": " + e);
  FetchAccess::Transfer manifest;
  manifest.begin = codec::kPackHeaderSize;
  manifest.end = manifest_end;
  manifest.head = &head;
  if (manifest.end > manifest.begin && !request(manifest)) return;
  FetchPlan plan;
  if (std::string e = plan_fetch(head, available, plan); !e.empty()) return fail(source_ + ": " + e);
  start_buffer(std::move(plan), head);
  // Chunks in file order, grouped into requests of about request_bytes, up to the planned size.
  const auto& chunks = plan_.info.chunks;
  const std::uint64_t limit = plan_.buffer;
  std::size_t c = 0;
  while (c < chunks.size() && !cancelled()) {
    const std::uint64_t begin = chunks[c].offset;
    std::uint64_t end = begin + chunks[c].size;
    ++c;
    while (c < chunks.size() && end - begin < options_.request_bytes) end += chunks[c++].size;
    end = std::min(end, limit);
    if (begin >= end) {
      if (begin >= limit) break;
      continue;  // zero-length chunks
    }
    FetchAccess::Transfer t;
    t.begin = begin;
    t.end = end;
    if (!request(t)) return;
  }
  if (!cancelled() && plan_.truncated())
    fail(source_ + ": truncated .gip pack (the server has " + std::to_string(plan_.buffer) + " of " +
         std::to_string(plan_.total) + " bytes)");
}

}  // namespace geomip::viewer
