// The MCAP writer and reader (record/mcap_writer.h, mcap_reader.h) and the datapack codec of
// recordings (record/datapack_codec.h).
#include <google/protobuf/descriptor.pb.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "nrp_protobuf/wrappers.pb.h"
#include "record/datapack_codec.h"
#include "record/mcap_reader.h"
#include "record/mcap_writer.h"

namespace fs = std::filesystem;
using namespace convoy;
using namespace convoy::record;

namespace {

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("convoy_mcap_test_" + std::to_string(getpid()) + name);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

uint64_t u64(const std::string& s, size_t at) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(s[at + i])) << (8 * i);
  return v;
}

// A file of `n` messages on two channels, in uncompressed chunks of `chunk` bytes (zstd:
// mcap_zstd_test.cpp).
fs::path write_file(int n, size_t chunk) {
  fs::path p = temp_file(std::to_string(n) + ".mcap");
  McapWriter w;
  w.open(p, "test", {chunk, McapCompression::kNone});
  uint16_t s = w.add_schema("convoy.JsonDataPack", "jsonschema", "{}");
  uint16_t a = w.add_channel("e/a", "json", s, {{"k", "v"}});
  uint16_t b = w.add_channel("e/b/in", "json", 0, {});
  w.write_metadata("convoy", {{"config", "{}"}});
  for (int i = 0; i < n; ++i)
    w.write_message(i % 2 ? b : a, i, uint64_t(i) * 10, uint64_t(i) * 10,
                    "{\"i\":" + std::to_string(i) + "}");
  EXPECT_EQ(w.close(), "");
  return p;
}

}  // namespace

TEST(McapWriter, FramingMagicFooterAndSummary) {
  fs::path p = write_file(1000, 4096);
  std::string f = slurp(p);
  ASSERT_GT(f.size(), 16u);
  EXPECT_EQ(f.substr(0, 8), std::string(kMcapMagic));
  EXPECT_EQ(f.substr(f.size() - 8), std::string(kMcapMagic));
  EXPECT_EQ(uint8_t(f[8]), kOpHeader);
  // Footer: op, length 20, summary_start, summary_offset_start, crc.
  const size_t footer = f.size() - 8 - 29;
  EXPECT_EQ(uint8_t(f[footer]), kOpFooter);
  EXPECT_EQ(u64(f, footer + 1), 20u);
  const uint64_t summary_start = u64(f, footer + 9), offsets_start = u64(f, footer + 17);
  EXPECT_LT(summary_start, offsets_start);
  EXPECT_EQ(uint8_t(f[summary_start]), kOpSchema);  // summary grouped by opcode, schemas first
  EXPECT_EQ(uint8_t(f[offsets_start]), kOpSummaryOffset);
  uint32_t crc;
  std::memcpy(&crc, f.data() + footer + 25, 4);
  EXPECT_EQ(crc,
            mcap_io::crc32(std::string_view(f).substr(summary_start, footer + 25 - summary_start)));
  // Data End just before the summary, with the CRC of everything before it.
  const size_t data_end = summary_start - 13;
  EXPECT_EQ(uint8_t(f[data_end]), kOpDataEnd);
  std::memcpy(&crc, f.data() + data_end + 9, 4);
  EXPECT_EQ(crc, mcap_io::crc32(std::string_view(f).substr(0, data_end)));
  fs::remove(p);
}

TEST(McapWriter, ChunksAndIndexesReadBack) {
  fs::path p = write_file(1000, 4096);
  McapReader r(p);
  McapMessage m;
  int n = 0;
  while (r.next(&m)) {
    EXPECT_EQ(m.sequence, uint32_t(n));
    EXPECT_EQ(m.log_time, uint64_t(n) * 10);
    EXPECT_EQ(m.data, "{\"i\":" + std::to_string(n) + "}");
    EXPECT_EQ(r.channels().at(m.channel).topic, n % 2 ? "e/b/in" : "e/a");
    ++n;
  }
  EXPECT_EQ(n, 1000);
  EXPECT_TRUE(r.complete()) << r.incomplete_reason();
  EXPECT_EQ(r.metadata().at("convoy").at("config"), "{}");
  EXPECT_EQ(r.channels().at(0).metadata.at("k"), "v");
  // Many chunks: each followed by its message indexes, each with a chunk index.
  std::string f = slurp(p);
  size_t chunks = 0;
  for (size_t at = 8; at < f.size() - 8;) {
    const uint8_t op = uint8_t(f[at]);
    if (op == kOpChunk) {
      ++chunks;
      const size_t after = at + 9 + u64(f, at + 1);
      // (the first chunk holds only the schema and channels: the metadata came next)
      if (chunks > 1) {
        EXPECT_EQ(uint8_t(f[after]), kOpMessageIndex);
      }
    }
    if (op == kOpDataEnd) break;
    at += 9 + u64(f, at + 1);
  }
  EXPECT_GT(chunks, 5u);
  fs::remove(p);
}

// A long run's summary (its chunk indexes alone over the writer's 1 MiB block) is written in
// blocks: it must still be one valid summary, with its CRC, offsets and footer.
TEST(McapWriter, ASummaryOverOneBlockIsWhole) {
  fs::path p = temp_file("long.mcap");
  McapWriter w;
  w.open(p, "test", {8192, McapCompression::kNone});
  const uint16_t s = w.add_schema("convoy.JsonDataPack", "jsonschema", "{}");
  std::vector<uint16_t> channels;
  for (int c = 0; c < 300; ++c)
    channels.push_back(w.add_channel("e/" + std::to_string(c), "json", s, {}));
  int n = 0;
  for (int round = 0; round < 600; ++round)
    for (uint16_t c : channels) {
      w.write_message(c, n, uint64_t(n), uint64_t(n), "{}");
      ++n;
    }
  ASSERT_EQ(w.close(), "");
  McapReader r(p);
  McapMessage m;
  int read = 0;
  while (r.next(&m)) ++read;
  r.read_to_end();
  EXPECT_EQ(read, n);
  EXPECT_TRUE(r.complete()) << r.incomplete_reason();
  const std::string f = slurp(p);
  const size_t footer = f.size() - 8 - 29;
  ASSERT_EQ(uint8_t(f[footer]), kOpFooter);
  const uint64_t summary_start = u64(f, footer + 9), offsets_start = u64(f, footer + 17);
  uint32_t crc;
  std::memcpy(&crc, f.data() + footer + 25, 4);
  EXPECT_EQ(crc,
            mcap_io::crc32(std::string_view(f).substr(summary_start, footer + 25 - summary_start)));
  // The chunk-index group's offset record: over a block long, and where the records are.
  bool found = false;
  for (size_t at = offsets_start; at < footer; at += 9 + u64(f, at + 1)) {
    ASSERT_EQ(uint8_t(f[at]), kOpSummaryOffset);
    if (uint8_t(f[at + 9]) != kOpChunkIndex) continue;
    found = true;
    const uint64_t start = u64(f, at + 10), length = u64(f, at + 18);
    EXPECT_GT(length, uint64_t(1) << 20);
    size_t records = 0, end = start;  // whole chunk-index records, exactly filling it
    for (; end < start + length; end += 9 + u64(f, end + 1), ++records)
      ASSERT_EQ(uint8_t(f[end]), kOpChunkIndex) << "at " << end;
    EXPECT_EQ(end, start + length);
    EXPECT_GT(records, 500u);
  }
  EXPECT_TRUE(found);
  fs::remove(p);
}

TEST(McapReader, CorruptionAndTruncationAreCaught) {
  fs::path p = write_file(200, 1024);
  std::string f = slurp(p);
  std::string bad = f;
  bad[600] ^= 0x20;  // inside the first chunk's records
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bad;
  try {
    McapReader r(p);
    r.read_to_end();
    FAIL() << "a flipped byte went unnoticed";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string() + ": "), std::string::npos) << e.what();
  }
  std::ofstream(p, std::ios::binary | std::ios::trunc) << f.substr(0, f.size() / 2);
  McapReader r(p);
  r.read_to_end();
  EXPECT_FALSE(r.complete());
  EXPECT_NE(r.incomplete_reason().find("cut short"), std::string::npos) << r.incomplete_reason();
  std::ofstream(p, std::ios::binary | std::ios::trunc) << "not mcap at all";
  EXPECT_THROW(McapReader{p}, McapError);
  fs::remove(p);
}

TEST(DataPackCodec, DoublesNeedingSeventeenDigitsRoundTrip) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("s");
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  const double x = 0.1 + 0.2;  // 0.30000000000000004
  const double tiny = 5e-324, third = 1.0 / 3.0;
  datapack::write_json(b, nlohmann::json{{"x", x},
                                         {"tiny", tiny},
                                         {"l", {third, -0.0, 1e308}},
                                         {"nan", std::nan("")},
                                         {"i", -7},
                                         {"u", 18446744073709551615ull}});
  Encoded e = encode(dp, datapack::inline_blob_reader(), false);
  EXPECT_EQ(e.kind, Kind::kJson);
  EXPECT_NE(e.data.find("\"x\":0.30000000000000004"), std::string::npos) << e.data;
  EXPECT_NE(e.data.find("{\"__float__\":\"nan\"}"), std::string::npos) << e.data;
  int placeholders = 0;
  engine::DataPack back = decode(e.kind, e.type, e.data, "s", "eng", &placeholders);
  nlohmann::json v = datapack::read_json(datapack::View(back, datapack::inline_blob_reader()));
  double got = v["x"].get<double>();
  EXPECT_EQ(std::memcmp(&got, &x, 8), 0);
  EXPECT_EQ(v["tiny"].get<double>(), tiny);
  EXPECT_EQ(v["l"][0].get<double>(), third);
  EXPECT_TRUE(std::signbit(v["l"][1].get<double>()));
  EXPECT_TRUE(std::isnan(v["nan"].get<double>()));
  EXPECT_EQ(v["u"].get<uint64_t>(), 18446744073709551615ull);
  // The recorded text of the decoded datapack is the same: replays compare by it.
  EXPECT_EQ(encode(back, datapack::inline_blob_reader(), false).data, e.data);
  EXPECT_EQ(placeholders, 0);
}

TEST(DataPackCodec, ProtobufWithItsSchemaAndBlobsAsStubs) {
  datapack::Registry::global().add<Wrappers::DoubleValue>();
  datapack::Registry::global().add<Wrappers::BytesValue>();
  engine::DataPack dp;
  dp.mutable_id()->set_name("v");
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  Wrappers::DoubleValue d;
  d.set_value(0.1 + 0.2);
  datapack::write_proto(b, d);
  Encoded e = encode(dp, datapack::inline_blob_reader(), false);
  EXPECT_EQ(e.kind, Kind::kProtobuf);
  EXPECT_EQ(e.type, "Wrappers.DoubleValue");
  EXPECT_EQ(e.data, d.SerializeAsString());
  google::protobuf::FileDescriptorSet fds;
  ASSERT_TRUE(fds.ParseFromString(datapack::Registry::global().file_descriptor_set(e.type)));
  bool found = false;
  for (const auto& f : fds.file())
    for (const auto& m : f.message_type()) found |= f.package() + "." + m.name() == e.type;
  EXPECT_TRUE(found);
  // A frame-sized bytes value travels as a blob: a stub without --record-blobs, the whole
  // message with it.
  engine::DataPack big;
  big.mutable_id()->set_name("frame");
  datapack::Builder bb(&big, writer);
  Wrappers::BytesValue bytes;
  bytes.set_value(std::string(100000, 'x'));
  datapack::write_proto(bb, bytes);
  ASSERT_EQ(big.blobs_size(), 1);
  Encoded s = encode(big, datapack::inline_blob_reader(), false);
  EXPECT_EQ(s.kind, Kind::kStub);
  EXPECT_LT(s.data.size(), 400u);
  EXPECT_NE(s.data.find("\"size\":100000"), std::string::npos) << s.data;
  int placeholders = 0;
  engine::DataPack zeros = decode(s.kind, s.type, s.data, "frame", "w", &placeholders);
  EXPECT_EQ(placeholders, 1);
  EXPECT_EQ(encode(zeros, datapack::inline_blob_reader(), false).data, s.data);
  Encoded full = encode(big, datapack::inline_blob_reader(), true);
  EXPECT_EQ(full.kind, Kind::kProtobuf);
  EXPECT_EQ(full.data, bytes.SerializeAsString());
}

TEST(DataPackCodec, Base64) {
  for (const std::string& s :
       std::vector<std::string>{"", "a", "ab", "abc", "abcd", std::string("\0\xff\x10", 3)})
    EXPECT_EQ(base64_decode(base64_encode(s)), s);
  EXPECT_EQ(base64_encode("Man"), "TWFu");
  EXPECT_EQ(base64_encode("Ma"), "TWE=");
}
