// Text that must be UTF-8 (protobuf `string` fields, JSON) made from bytes that may not be: an
// exception message naming a file or a datapack carries whatever bytes it was given.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace convoy {

// `bytes` with every byte that does not start a well-formed UTF-8 sequence (overlong forms,
// surrogates and code points past U+10FFFF included) replaced by U+FFFD.
inline std::string valid_utf8(std::string_view bytes) {
  std::string out;
  out.reserve(bytes.size());
  const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
  const size_t n = bytes.size();
  for (size_t i = 0; i < n;) {
    const uint8_t c = p[i];
    size_t len = c < 0x80           ? 1
                 : (c >> 5) == 0x6  ? 2
                 : (c >> 4) == 0xe  ? 3
                 : (c >> 3) == 0x1e ? 4
                                    : 0;
    if (len > 1) {
      uint32_t cp = c & (0x7f >> len);
      for (size_t k = 1; k < len; ++k) {
        if (i + k >= n || (p[i + k] & 0xc0) != 0x80) {
          len = 0;
          break;
        }
        cp = (cp << 6) | (p[i + k] & 0x3f);
      }
      static constexpr uint32_t kMin[5] = {0, 0, 0x80, 0x800, 0x10000};
      if (len && (cp < kMin[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))) len = 0;
    }
    if (len == 0) {
      out += "\xef\xbf\xbd";
      ++i;
      continue;
    }
    out.append(bytes.substr(i, len));
    i += len;
  }
  return out;
}

}  // namespace convoy
