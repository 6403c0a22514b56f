// JSON text straight from a JSON datapack's MessagePack bytes (json.h, json_text): the text
// nlohmann::json's dump() writes of the value read_json() reads, without building that value
// (a std::map node per key, a heap object per number): keys sorted (the last of equal keys
// kept), numbers written by nlohmann's own formatter. Anything it is not sure of makes it
// give up, and json_text() then goes the long way.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "datapack/json.h"

namespace convoy::datapack {

namespace {

// Deeper nesting goes the long way (which refuses more than kMaxJsonDepth levels).
constexpr int kMaxDepth = 64;

class MsgpackJson {
 public:
  explicit MsgpackJson(std::string_view bytes)
      : p_(reinterpret_cast<const uint8_t*>(bytes.data())), end_(p_ + bytes.size()) {}

  bool convert(std::string* out) { return value(out, 0) && p_ == end_; }

 private:
  bool value(std::string* out, int depth);
  bool container(std::string* out, uint8_t c, int depth);

  // A big-endian unsigned integer of n bytes.
  bool read(size_t n, uint64_t* v) {
    if (static_cast<size_t>(end_ - p_) < n) return false;
    *v = 0;
    for (size_t i = 0; i < n; ++i) *v = (*v << 8) | *p_++;
    return true;
  }

  // A string of n bytes (ASCII only: nlohmann checks UTF-8, the long way does too).
  bool string(size_t n, std::string_view* s) {
    if (static_cast<size_t>(end_ - p_) < n) return false;
    *s = std::string_view(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    return std::none_of(s->begin(), s->end(), [](char c) { return c & 0x80; });
  }

  // A string's length from its marker byte c (false: c is no string).
  bool string_length(uint8_t c, size_t* n) {
    uint64_t v = 0;
    if (c >= 0xa0 && c <= 0xbf) {
      v = c & 0x1f;
    } else if (c >= 0xd9 && c <= 0xdb) {
      if (!read(size_t{1} << (c - 0xd9), &v)) return false;
    } else {
      return false;
    }
    *n = static_cast<size_t>(v);
    return true;
  }

  const uint8_t* p_;
  const uint8_t* end_;
};

// nlohmann's dump_escaped for ASCII text (ensure_ascii off).
void escaped(std::string_view s, std::string* out) {
  out->push_back('"');
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '\b':
        out->append("\\b");
        break;
      case '\t':
        out->append("\\t");
        break;
      case '\n':
        out->append("\\n");
        break;
      case '\f':
        out->append("\\f");
        break;
      case '\r':
        out->append("\\r");
        break;
      case '"':
        out->append("\\\"");
        break;
      case '\\':
        out->append("\\\\");
        break;
      default:
        if (c <= 0x1f) {
          static constexpr char kHex[] = "0123456789abcdef";
          out->append("\\u00");
          out->push_back(kHex[c >> 4]);
          out->push_back(kHex[c & 0xf]);
        } else {
          out->push_back(ch);
        }
    }
  }
  out->push_back('"');
}

// nlohmann's dump_float: null when not finite, else its shortest round-trip digits.
void number(double v, std::string* out) {
  if (!std::isfinite(v)) {
    out->append("null");
    return;
  }
  char buf[64];
  char* end = nlohmann::detail::to_chars(buf, buf + sizeof buf, v);
  out->append(buf, end);
}

template <typename T>
void integer(T v, std::string* out) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out->append(buf, r.ptr);
}

bool MsgpackJson::value(std::string* out, int depth) {
  if (p_ >= end_) return false;
  const uint8_t c = *p_++;
  uint64_t v = 0;
  if (c <= 0x7f) return integer(uint64_t{c}, out), true;
  if (c >= 0xe0) return integer(int64_t{static_cast<int8_t>(c)}, out), true;
  if (c <= 0x9f || c == 0xdc || c == 0xdd || c == 0xde || c == 0xdf)
    return container(out, c, depth);
  if (size_t n = 0; string_length(c, &n)) {
    std::string_view s;
    if (!string(n, &s)) return false;
    escaped(s, out);
    return true;
  }
  switch (c) {
    case 0xc0:
      out->append("null");
      return true;
    case 0xc2:
      out->append("false");
      return true;
    case 0xc3:
      out->append("true");
      return true;
    case 0xca: {
      if (!read(4, &v)) return false;
      float f;
      const auto bits = static_cast<uint32_t>(v);
      std::memcpy(&f, &bits, sizeof f);
      number(static_cast<double>(f), out);
      return true;
    }
    case 0xcb: {
      if (!read(8, &v)) return false;
      double d;
      std::memcpy(&d, &v, sizeof d);
      number(d, out);
      return true;
    }
    case 0xcc:
    case 0xcd:
    case 0xce:
    case 0xcf:
      if (!read(size_t{1} << (c - 0xcc), &v)) return false;
      integer(v, out);
      return true;
    case 0xd0:
    case 0xd1:
    case 0xd2:
    case 0xd3: {
      const size_t n = size_t{1} << (c - 0xd0);
      if (!read(n, &v)) return false;
      const int shift = static_cast<int>(64 - 8 * n);  // sign-extend n bytes
      integer(static_cast<int64_t>(v << shift) >> shift, out);
      return true;
    }
    default:  // binary and extension values (numpy arrays), 0xc1
      return false;
  }
}

bool MsgpackJson::container(std::string* out, uint8_t c, int depth) {
  if (depth >= kMaxDepth) return false;
  const bool map = (c >= 0x80 && c <= 0x8f) || c == 0xde || c == 0xdf;
  uint64_t n = c & 0x0f;
  if (c >= 0xdc && !read(c == 0xdc || c == 0xde ? 2 : 4, &n)) return false;
  if (!map) {
    out->push_back('[');
    for (uint64_t i = 0; i < n; ++i) {
      if (i) out->push_back(',');
      if (!value(out, depth + 1)) return false;
    }
    out->push_back(']');
    return true;
  }
  std::vector<std::pair<std::string_view, std::string>> items;  // key, value's text
  for (uint64_t i = 0; i < n; ++i) {
    size_t length = 0;
    std::string_view key;
    if (p_ >= end_ || !string_length(*p_++, &length) || !string(length, &key)) return false;
    items.emplace_back(key, std::string());
    if (!value(&items.back().second, depth + 1)) return false;
  }
  // nlohmann's object is a std::map: keys in order, a repeated key's last value kept.
  std::stable_sort(items.begin(), items.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  out->push_back('{');
  bool first = true;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i + 1 < items.size() && items[i + 1].first == items[i].first) continue;
    if (!first) out->push_back(',');
    first = false;
    escaped(items[i].first, out);
    out->push_back(':');
    out->append(items[i].second);
  }
  out->push_back('}');
  return true;
}

}  // namespace

bool msgpack_json_text(std::string_view msgpack, std::string* out) {
  out->clear();
  return MsgpackJson(msgpack).convert(out);
}

std::string json_text(const View& in) {
  if (in.is_json()) {
    std::string out;
    if (msgpack_json_text(in.message().json_msgpack(), &out)) return out;
  }
  return read_json(in).dump();
}

}  // namespace convoy::datapack
