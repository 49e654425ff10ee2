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

std::string one_line(std::string_view message, std::size_t max_bytes) {
  std::string out;
  std::size_t i = 0;
  while (i < message.size()) {
    if (out.size() >= max_bytes) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(message[i]);
    std::size_t len = c < 0x80             ? 1
                      : (c & 0xE0) == 0xC0 ? 2
                      : (c & 0xF0) == 0xE0 ? 3
                      : (c & 0xF8) == 0xF0 ? 4
                                           : 0;
    bool valid = len > 0 && i + len <= message.size() && !(len == 2 && c < 0xC2) && !(len == 4 && c > 0xF4);
    for (std::size_t k = 1; valid && k < len; ++k)
      valid = (static_cast<unsigned char>(message[i + k]) & 0xC0) == 0x80;
    if (valid && len == 3) {  // no overlong forms, no UTF-16 surrogates
      const auto c1 = static_cast<unsigned char>(message[i + 1]);
      valid = !(c == 0xE0 && c1 < 0xA0) && !(c == 0xED && c1 >= 0xA0);
    }
    if (valid && len == 4) {
      const auto c1 = static_cast<unsigned char>(message[i + 1]);
      valid = !(c == 0xF0 && c1 < 0x90) && !(c == 0xF4 && c1 >= 0x90);
    }
    if (!valid) {
      out.push_back('?');
      ++i;
    } else if (len == 1) {
      out.push_back(c < 0x20 || c == 0x7F ? '?' : static_cast<char>(c));
      ++i;
    } else {
      out.append(message.substr(i, len));
      i += len;
    }
  }
  return out;
}

}  // namespace geomip::codec
