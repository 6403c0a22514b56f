// Writing text files with errors that name the file: what mesh_io.cpp and the world
// generator's writers share.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace convoy::opendrive {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

inline File open_for_writing(const std::filesystem::path& path) {
  File f(std::fopen(path.c_str(), "w"));
  if (!f) throw std::runtime_error(path.string() + ": cannot write: " + std::strerror(errno));
  return f;
}

// Closes `f`; throws naming `path` when a write or the close failed (a full disk).
inline void close_checked(File f, const std::filesystem::path& path) {
  const bool bad = std::ferror(f.get()) != 0;
  if (std::fclose(f.release()) != 0 || bad) {
    throw std::runtime_error(path.string() + ": write failed: " + std::strerror(errno));
  }
}

}  // namespace convoy::opendrive
