// msgpack_json_text (datapack/json.h): the text nlohmann's dump() writes of the value its
// MessagePack reader reads, or false for the cases left to nlohmann.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "datapack/json.h"

namespace convoy::datapack {
namespace {

using nlohmann::json;

std::string packed(const json& v) {
  std::string out;
  json::to_msgpack(v, nlohmann::detail::output_adapter<char>(out));
  return out;
}

// The text nlohmann gives of MessagePack bytes (what json_text does the long way).
std::string long_way(const std::string& bytes) { return json::from_msgpack(bytes).dump(); }

void expect_same(const std::string& bytes) {
  std::string text;
  ASSERT_TRUE(msgpack_json_text(bytes, &text));
  EXPECT_EQ(text, long_way(bytes));
}

json random_value(std::mt19937_64& rng, int depth) {
  std::uniform_int_distribution<int> kind(0, depth > 3 ? 5 : 7);
  switch (kind(rng)) {
    case 0:
      return nullptr;
    case 1:
      return static_cast<bool>(rng() & 1);
    case 2:
      return static_cast<int64_t>(rng()) >> (rng() % 64);
    case 3:
      return rng() >> (rng() % 64);
    case 4: {
      double d;
      uint64_t bits = rng();
      std::memcpy(&d, &bits, sizeof d);
      return std::isfinite(d) ? d : std::ldexp(static_cast<double>(rng() % 1000), -20);
    }
    case 5: {
      std::string s;
      for (int i = rng() % 12; i > 0; --i) s.push_back(static_cast<char>(rng() % 128));
      return s;
    }
    case 6: {
      json a = json::array();
      for (int i = rng() % 6; i > 0; --i) a.push_back(random_value(rng, depth + 1));
      return a;
    }
    default: {
      json o = json::object();
      for (int i = rng() % 6; i > 0; --i)
        o[std::string(1, static_cast<char>('a' + rng() % 5)) + std::to_string(rng() % 3)] =
            random_value(rng, depth + 1);
      return o;
    }
  }
}

TEST(MsgpackJson, RandomValuesAsNlohmannWritesThem) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 3000; ++i) expect_same(packed(random_value(rng, 0)));
}

TEST(MsgpackJson, NumbersAndEscapes) {
  for (double d : {0.0, -0.0, 1.0, -1.5, 0.1, 1e-5, 1e-4, 123456789012345.0, 1e15, 1e16, 1e300,
                   5e-324, std::numeric_limits<double>::max(), 4.794219031431874})
    expect_same(packed(d));
  expect_same(
      packed(json::array({std::numeric_limits<int64_t>::min(), std::numeric_limits<uint64_t>::max(),
                          -1, -32, -33, 127, 128, 65535, 65536})));
  expect_same(packed("quote \" backslash \\ / \b\f\n\r\t \x01\x1f\x7f"));
  expect_same(packed(json::object()));
  expect_same(packed(json::array()));
  // float32, NaN and infinity (as nlohmann writes them: null)
  expect_same(std::string("\xca\x3d\xcc\xcc\xcd", 5));
  expect_same(std::string("\xcb\x7f\xf8\0\0\0\0\0\0", 9));
  expect_same(std::string("\xca\xff\x80\0\0", 5));
}

TEST(MsgpackJson, KeysSortedTheLastOfEqualKeysKept) {
  // {"b": 1, "a": 2, "b": 3} as written by a Python dict's encoder would not repeat a key,
  // but the bytes may: nlohmann keeps the last.
  const std::string bytes(
      "\x83\xa1"
      "b\x01\xa1"
      "a\x02\xa1"
      "b\x03",
      10);
  std::string text;
  ASSERT_TRUE(msgpack_json_text(bytes, &text));
  EXPECT_EQ(text, R"({"a":2,"b":3})");
  EXPECT_EQ(text, long_way(bytes));
}

TEST(MsgpackJson, LeavesToNlohmannWhatItIsNotSureOf) {
  std::string text;
  EXPECT_FALSE(msgpack_json_text(packed("caf\xc3\xa9"), &text));            // non-ASCII
  EXPECT_FALSE(msgpack_json_text(packed(json::binary({1, 2}, 3)), &text));  // ext
  EXPECT_FALSE(msgpack_json_text(std::string("\x81\x01\x02", 3), &text));   // int key
  EXPECT_FALSE(msgpack_json_text(std::string("\x92\x01", 2), &text));       // truncated
  EXPECT_FALSE(msgpack_json_text(std::string("\x01\x02", 2), &text));       // trailing
  EXPECT_FALSE(msgpack_json_text(std::string(), &text));
  EXPECT_FALSE(msgpack_json_text(std::string("\xc1", 1), &text));
  std::string deep(100, '\x91');
  deep.push_back('\x01');
  EXPECT_FALSE(msgpack_json_text(deep, &text));
  std::string shallow(60, '\x91');
  shallow.push_back('\x01');
  expect_same(shallow);
}

}  // namespace
}  // namespace convoy::datapack
