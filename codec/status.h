// Status codes of geomip's byte decoders. Decoders of bytes from disk or network never throw or assert on
// data (../shared/STYLE.md): they return one of these.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace geomip::codec {

enum class Status {
  kOk = 0,
  kTruncated,           ///< the bytes end before the structure does: wait for more, or decode what is there
  kCorrupt,             ///< the bytes contradict themselves (bad magic, CRC mismatch, impossible sizes)
  kUnsupportedVersion,  ///< a valid pack of a format version this build does not read
  kInvalidArgument,     ///< the caller asked for something impossible (level beyond the pack, bad options)
};

/// Every status has exactly one message, here (a test checks that each code has one).
std::string_view status_message(Status status);

/// `message` made fit for one terminal line, for every error a tool prints (file and server data can reach a
/// message: a parser quoting the garbage it stopped at, a server's reason phrase): control characters
/// (newlines, escapes) and bytes that are not valid UTF-8 (overlong forms, surrogates, above U+10FFFF,
/// truncated sequences) become '?'; valid UTF-8, such as a user's file names, is kept; cut after `max_bytes`
/// bytes at a character boundary, with "..." appended.
std::string one_line(std::string_view message, std::size_t max_bytes = 400);

/// Number of Status codes, for tests that enumerate them.
inline constexpr int kStatusCount = 5;

}  // namespace geomip::codec
