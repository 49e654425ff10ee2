#include "codec/status.h"

namespace geomip::codec {

std::string_view status_message(Status status) {
  switch (status) {
    case Status::kOk: return "ok";
    case Status::kTruncated: return "truncated: the data ends before the structure it announces";
    case Status::kCorrupt: return "corrupt: the data is inconsistent (bad magic, checksum or sizes)";
    case Status::kUnsupportedVersion: return "unsupported version: written by a newer or unknown format version";
    case Status::kInvalidArgument: return "invalid argument";
  }
  return "";  // unreachable for valid enum values; an unknown value has no message (the test catches it)
}

}  // namespace geomip::codec
