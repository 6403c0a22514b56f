#include "road_user_wire/road_user_wire.h"

#include <cstdint>
#include <cstring>

namespace convoy::road_user_wire {
namespace {

enum WireType : uint32_t { kVarint = 0, kFixed64 = 1, kBytes = 2, kFixed32 = 5 };

// The field numbers of road_users.proto.
enum Field : uint32_t {
  kId = 1,
  kCategory = 2,
  kAbsent = 4,
  kX = 5,
  kY = 6,
  kYaw = 8,
  kSpeed = 11,
  kLength = 16,
  kWidth = 17,
  kLengthOffset = 19,
};
constexpr uint32_t kUsers = 1;  // RoadUsers.users

class Reader {
 public:
  explicit Reader(std::string_view bytes) : p_(bytes.data()), end_(bytes.data() + bytes.size()) {}
  bool done() const { return p_ == end_; }

  bool varint(uint64_t* v) {
    *v = 0;
    for (int shift = 0; shift < 64 && p_ < end_; shift += 7) {
      const auto b = static_cast<uint8_t>(*p_++);
      *v |= static_cast<uint64_t>(b & 0x7F) << shift;
      if (!(b & 0x80)) return true;
    }
    return false;
  }
  bool fixed64(double* v) {
    if (end_ - p_ < 8) return false;
    std::memcpy(v, p_, 8);  // little-endian, as x86 and arm64
    p_ += 8;
    return true;
  }
  bool bytes(std::string_view* v) {
    uint64_t n = 0;
    if (!varint(&n) || n > static_cast<uint64_t>(end_ - p_)) return false;
    *v = std::string_view(p_, n);
    p_ += n;
    return true;
  }
  // Skips a field of `type` whose tag was read.
  bool skip(uint32_t type) {
    uint64_t v = 0;
    double d = 0;
    std::string_view s;
    switch (type) {
      case kVarint:
        return varint(&v);
      case kFixed64:
        return fixed64(&d);
      case kBytes:
        return bytes(&s);
      case kFixed32:
        if (end_ - p_ < 4) return false;
        p_ += 4;
        return true;
      default:
        return false;  // groups (deprecated) and invalid types
    }
  }

 private:
  const char* p_;
  const char* end_;
};

double* double_field(UserFields* u, uint32_t field) {
  switch (field) {
    case kX:
      return &u->x;
    case kY:
      return &u->y;
    case kYaw:
      return &u->yaw;
    case kSpeed:
      return &u->speed;
    case kLength:
      return &u->length;
    case kWidth:
      return &u->width;
    case kLengthOffset:
      return &u->length_offset;
    default:
      return nullptr;
  }
}

}  // namespace

bool read_user(std::string_view bytes, UserFields* out) {
  *out = {};
  Reader r(bytes);
  while (!r.done()) {
    uint64_t tag = 0;
    if (!r.varint(&tag) || tag >> 3 == 0 || tag >> 3 > UINT32_MAX) return false;
    const auto field = static_cast<uint32_t>(tag >> 3), type = static_cast<uint32_t>(tag & 7);
    double* d = double_field(out, field);
    bool ok = false;
    if (d && type == kFixed64) {
      ok = r.fixed64(d);
    } else if ((field == kId || field == kCategory) && type == kBytes) {
      ok = r.bytes(field == kId ? &out->id : &out->category);
    } else if (field == kAbsent && type == kVarint) {
      uint64_t v = 0;
      ok = r.varint(&v);
      out->absent = v != 0;
    } else {
      ok = r.skip(type);  // another field (or a known one in an unexpected wire type)
    }
    if (!ok) return false;
  }
  return true;
}

bool for_each_user(std::string_view bytes, const std::function<void(const UserFields&)>& visit) {
  Reader r(bytes);
  UserFields u;
  while (!r.done()) {
    uint64_t tag = 0;
    if (!r.varint(&tag) || tag >> 3 == 0) return false;
    if (tag == (kUsers << 3 | kBytes)) {
      std::string_view user;
      if (!r.bytes(&user) || !read_user(user, &u)) return false;
      visit(u);
    } else if (!r.skip(static_cast<uint32_t>(tag & 7))) {
      return false;
    }
  }
  return true;
}

}  // namespace convoy::road_user_wire
