// Status codes of geomip's byte decoders. Decoders of bytes from disk or network never throw or assert on
// data (../shared/STYLE.md): they return one of these.
#pragma once

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

/// Number of Status codes, for tests that enumerate them.
inline constexpr int kStatusCount = 5;

}  // namespace geomip::codec
