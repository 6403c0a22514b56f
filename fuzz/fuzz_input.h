// Shared by the fuzz targets and the seed generator: how a fuzz input is cut into parts.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace convoy::fuzz {

// Stops the run with a message: a decoder accepted something it should not have.
[[noreturn]] inline void fail(const char* what) {
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

// `[u8 n]`, then n times `[u16 LE size][bytes]`, then the payload: a datapack's blobs and its
// payload from one input. A short input gives fewer blobs.
struct BlobbedInput {
  std::vector<std::string_view> blobs;
  std::string_view payload;
};
inline BlobbedInput split_blobs(std::string_view in) {
  BlobbedInput out;
  if (in.empty()) return out;
  size_t n = static_cast<uint8_t>(in[0]) % 8;
  in.remove_prefix(1);
  for (; n > 0 && in.size() >= 2; --n) {
    size_t size = static_cast<uint8_t>(in[0]) | (size_t{static_cast<uint8_t>(in[1])} << 8);
    in.remove_prefix(2);
    if (size > in.size()) size = in.size();
    out.blobs.push_back(in.substr(0, size));
    in.remove_prefix(size);
  }
  out.payload = in;
  return out;
}
inline std::string join_blobs(const std::vector<std::string>& blobs, std::string_view payload) {
  std::string out(1, static_cast<char>(blobs.size()));
  for (const auto& b : blobs) {
    if (b.size() > 0xffff) throw std::length_error("seed blob too large");
    out += static_cast<char>(b.size() & 0xff);
    out += static_cast<char>(b.size() >> 8);
    out += b;
  }
  out += payload;
  return out;
}

// Parts separated by NUL bytes (a config text and its `-o` overrides).
inline std::vector<std::string> split_nul(std::string_view in, size_t max_parts) {
  std::vector<std::string> parts;
  while (parts.size() + 1 < max_parts) {
    size_t nul = in.find('\0');
    if (nul == std::string_view::npos) break;
    parts.emplace_back(in.substr(0, nul));
    in.remove_prefix(nul + 1);
  }
  parts.emplace_back(in);
  return parts;
}

}  // namespace convoy::fuzz
