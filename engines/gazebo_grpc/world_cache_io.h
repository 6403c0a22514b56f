// The parsed-world cache's binary writer and reader (world_cache.cpp): plain values, strings,
// paths and fixed-size Eigen matrices, little-endian as in memory. Internal to the cache.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "world_description.h"

namespace convoy::world::cache_io {

namespace fs = std::filesystem;

class Writer {
 public:
  template <typename T>
  void pod(const T& v) {
    // Plain values and fixed-size Eigen matrices (a plain array of doubles).
    out_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void str(const std::string& s) {
    pod<uint64_t>(s.size());
    out_ += s;
  }
  void path(const fs::path& p) { str(p.string()); }
  void iso(const Eigen::Isometry3d& t) { pod(t.matrix()); }
  void v3(const Eigen::Vector3d& v) { pod(v); }
  void rgba(const Rgba& c) { pod(c); }
  void size(size_t n) { pod<uint64_t>(n); }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  template <typename T>
  T pod() {
    // Plain values and fixed-size Eigen matrices (a plain array of doubles).
    need(sizeof(T));
    T v;
    std::memcpy(static_cast<void*>(&v), in_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::string str() {
    auto n = pod<uint64_t>();
    need(n);
    std::string s = in_.substr(at_, n);
    at_ += n;
    return s;
  }
  fs::path path() { return str(); }
  Eigen::Isometry3d iso() {
    Eigen::Isometry3d t;
    t.matrix() = pod<Eigen::Matrix4d>();
    return t;
  }
  Eigen::Vector3d v3() { return pod<Eigen::Vector3d>(); }
  Rgba rgba() { return pod<Rgba>(); }
  size_t size() {
    auto n = pod<uint64_t>();
    if (n > in_.size()) throw std::runtime_error("corrupt count");
    return n;
  }
  bool done() const { return at_ == in_.size(); }

 private:
  void need(size_t n) const {
    if (n > in_.size() - at_) throw std::runtime_error("truncated");
  }
  const std::string& in_;
  size_t at_ = 0;
};

}  // namespace convoy::world::cache_io
