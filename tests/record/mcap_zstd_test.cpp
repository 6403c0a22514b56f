// zstd-compressed MCAP chunks (record/mcap_writer.h, mcap_reader.h): the chunk fields and
// indexes the specification asks for, CRCs, files without compression (all recordings before
// zstd), files cut short by a killed writer; and the recording's camera channels in
// Foxglove's schemas (record/recorder.h).
#include <gtest/gtest.h>
#include <zstd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "datapack/camera.h"
#include "record/datapack_codec.h"
#include "record/mcap_reader.h"
#include "record/mcap_writer.h"
#include "record/recorder.h"

namespace fs = std::filesystem;
using namespace convoy;
using namespace convoy::record;

namespace {

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("convoy_mcap_zstd_test_" + std::to_string(getpid()) + name);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void spit(const fs::path& p, std::string_view bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
}

uint64_t read_uint(std::string_view s, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= uint64_t(uint8_t(s[at + i])) << (8 * i);
  return v;
}

// A Chunk record of the data section, its fields as the specification lays them out.
struct Chunk {
  size_t offset = 0, end = 0;  // of the record in the file
  uint64_t start_time = 0, end_time = 0, uncompressed_size = 0;
  uint32_t crc = 0;
  std::string compression;
  size_t crc_at = 0;  // where the uncompressed_crc field is
  std::string_view records;
};

std::vector<Chunk> chunks_of(std::string_view f) {
  std::vector<Chunk> out;
  for (size_t at = 8; at + 9 <= f.size();) {
    const uint8_t op = uint8_t(f[at]);
    const uint64_t len = read_uint(f, at + 1, 8);
    if (at + 9 + len > f.size()) break;
    if (op == kOpChunk) {
      Chunk c;
      c.offset = at;
      c.end = at + 9 + len;
      size_t p = at + 9;
      c.start_time = read_uint(f, p, 8);
      c.end_time = read_uint(f, p + 8, 8);
      c.uncompressed_size = read_uint(f, p + 16, 8);
      c.crc_at = p + 24;
      c.crc = uint32_t(read_uint(f, p + 24, 4));
      const uint32_t n = uint32_t(read_uint(f, p + 28, 4));
      c.compression = std::string(f.substr(p + 32, n));
      const uint64_t records = read_uint(f, p + 32 + n, 8);
      c.records = f.substr(p + 40 + n, records);
      out.push_back(c);
    }
    if (op == kOpDataEnd) break;
    at += 9 + len;
  }
  return out;
}

std::string payload(int i) {
  return R"({"pose":{"x":)" + std::to_string(i * 0.25) + R"(,"y":12.5,"yaw":0.1},"id":)" +
         std::to_string(i) + "}";
}

// `n` messages on two channels, in chunks of `chunk` uncompressed bytes.
fs::path write_file(const std::string& name, int n, size_t chunk, McapCompression compression) {
  fs::path p = temp_file(name);
  McapWriter w;
  w.open(p, "test", {chunk, compression});
  const uint16_t s = w.add_schema("convoy.JsonDataPack", "jsonschema", "{}");
  const uint16_t a = w.add_channel("e/a", "json", s, {});
  const uint16_t b = w.add_channel("e/b", "json", s, {});
  w.write_metadata("convoy", {{"config", "{}"}});
  for (int i = 0; i < n; ++i)
    w.write_message(i % 2 ? b : a, i, uint64_t(i) * 10, uint64_t(i) * 10, payload(i));
  EXPECT_EQ(w.close(), "");
  return p;
}

int read_all(const fs::path& p, McapReader* r = nullptr) {
  std::optional<McapReader> own;
  if (!r) r = &own.emplace(p);
  McapMessage m;
  int n = 0;
  while (r->next(&m)) {
    EXPECT_EQ(m.sequence, uint32_t(n));
    EXPECT_EQ(m.log_time, uint64_t(n) * 10);
    EXPECT_EQ(m.data, payload(n));
    ++n;
  }
  return n;
}

}  // namespace

TEST(McapZstd, ChunksRoundTripWithTheFieldsReadersExpect) {
  const fs::path p = write_file("round_trip.mcap", 20000, 64 << 10, McapCompression::kZstd);
  const std::string f = slurp(p);
  const std::vector<Chunk> chunks = chunks_of(f);
  ASSERT_GT(chunks.size(), 5u);
  uint64_t compressed = 0, uncompressed = 0;
  for (const Chunk& c : chunks) {
    if (c.records.size() < 200) continue;  // the first: schema and channels only
    EXPECT_EQ(c.compression, "zstd");
    EXPECT_LT(c.records.size() * 4, c.uncompressed_size) << "JSON compresses well";
    std::string raw(c.uncompressed_size, '\0');
    ASSERT_EQ(ZSTD_decompress(raw.data(), raw.size(), c.records.data(), c.records.size()),
              c.uncompressed_size);
    EXPECT_EQ(c.crc, mcap_io::crc32(raw)) << "the CRC is the uncompressed records'";
    EXPECT_LE(c.start_time, c.end_time);
    compressed += c.records.size();
    uncompressed += c.uncompressed_size;
  }
  EXPECT_LT(compressed * 4, uncompressed);

  // The chunk indexes in the summary name the compression and both sizes.
  const size_t footer = f.size() - 8 - 29;
  const uint64_t summary_start = read_uint(f, footer + 9, 8);
  size_t indexes = 0;
  for (size_t at = summary_start; at < footer;) {
    const uint64_t len = read_uint(f, at + 1, 8);
    if (uint8_t(f[at]) == kOpChunkIndex) {
      size_t q = at + 9;
      const uint64_t offset = read_uint(f, q + 16, 8), length = read_uint(f, q + 24, 8);
      q += 32;
      q += 4 + read_uint(f, q, 4);  // message index offsets
      q += 8;                       // message index length
      const uint32_t n = uint32_t(read_uint(f, q, 4));
      const std::string compression = f.substr(q + 4, n);
      const uint64_t csize = read_uint(f, q + 4 + n, 8), usize = read_uint(f, q + 12 + n, 8);
      const Chunk& c = chunks.at(indexes);
      EXPECT_EQ(offset, c.offset);
      EXPECT_EQ(length, c.end - c.offset);
      EXPECT_EQ(compression, c.compression);
      EXPECT_EQ(csize, c.records.size());
      EXPECT_EQ(usize, c.uncompressed_size);
      ++indexes;
    }
    at += 9 + len;
  }
  EXPECT_EQ(indexes, chunks.size());

  McapReader r(p);
  EXPECT_EQ(read_all(p, &r), 20000);
  EXPECT_TRUE(r.complete()) << r.incomplete_reason();
  EXPECT_EQ(r.metadata().at("convoy").at("config"), "{}");
  fs::remove(p);
}

TEST(McapZstd, ACrcOrAByteThatDoesNotMatchIsCaught) {
  const fs::path p = write_file("crc.mcap", 5000, 16 << 10, McapCompression::kZstd);
  const std::string f = slurp(p);
  const Chunk c = chunks_of(f).at(2);
  ASSERT_EQ(c.compression, "zstd");
  std::string bad = f;
  bad[c.crc_at] ^= 0x01;
  spit(p, bad);
  try {
    read_all(p);
    FAIL() << "a wrong chunk CRC went unnoticed";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("Chunk CRC does not match"), std::string::npos)
        << e.what();
  }
  bad = f;
  bad[c.records.data() - f.data() + c.records.size() / 2] ^= 0x40;
  spit(p, bad);
  EXPECT_THROW(read_all(p), McapError);
  fs::remove(p);
}

TEST(McapZstd, UncompressedFilesAreStillRead) {
  // McapCompression::kNone writes the bytes of the writer before zstd, byte for byte.
  const fs::path p = write_file("plain.mcap", 3000, 8 << 10, McapCompression::kNone);
  const std::string f = slurp(p);
  for (const Chunk& c : chunks_of(f)) {
    EXPECT_EQ(c.compression, "");
    EXPECT_EQ(c.records.size(), c.uncompressed_size);
  }
  McapReader r(p);
  EXPECT_EQ(read_all(p, &r), 3000);
  EXPECT_TRUE(r.complete()) << r.incomplete_reason();
  fs::remove(p);
}

TEST(McapZstd, AFileCutShortReadsUpToItsLastWholeChunk) {
  const fs::path p = write_file("cut.mcap", 8000, 8 << 10, McapCompression::kZstd);
  const std::string f = slurp(p);
  const std::vector<Chunk> chunks = chunks_of(f);
  ASSERT_GT(chunks.size(), 6u);
  // Messages in the chunks before the fifth (the first holds no message).
  int before = 0;
  for (size_t i = 0; i < 4; ++i) {
    std::string raw(chunks[i].uncompressed_size, '\0');
    if (chunks[i].compression == "zstd")
      ZSTD_decompress(raw.data(), raw.size(), chunks[i].records.data(), chunks[i].records.size());
    else
      raw = chunks[i].records;
    for (size_t at = 0; at < raw.size(); at += 9 + read_uint(raw, at + 1, 8))
      before += uint8_t(raw[at]) == kOpMessage;
  }
  ASSERT_GT(before, 0);
  const Chunk& fifth = chunks[4];
  spit(p, std::string_view(f).substr(0, fifth.offset + (fifth.end - fifth.offset) / 2));
  McapReader r(p);
  EXPECT_EQ(read_all(p, &r), before);
  EXPECT_FALSE(r.complete());
  EXPECT_NE(r.incomplete_reason().find("cut short"), std::string::npos) << r.incomplete_reason();
  fs::remove(p);
}

TEST(McapZstd, AKilledWriterLosesOnlyItsOpenChunk) {
  const fs::path p = temp_file("killed.mcap");
  const fs::path copy = temp_file("killed_copy.mcap");
  {
    McapWriter w;
    w.open(p, "test", {4 << 10, McapCompression::kZstd});
    const uint16_t s = w.add_schema("convoy.JsonDataPack", "jsonschema", "{}");
    const uint16_t a = w.add_channel("e/a", "json", s, {});
    const uint16_t b = w.add_channel("e/b", "json", s, {});
    for (int i = 0; i < 1000; ++i)
      w.write_message(i % 2 ? b : a, i, uint64_t(i) * 10, uint64_t(i) * 10, payload(i));
    // What the disk holds now is what a crash would leave.
    fs::copy_file(p, copy, fs::copy_options::overwrite_existing);
    McapReader r(copy);
    const int read = read_all(copy, &r);
    EXPECT_FALSE(r.complete());
    EXPECT_LT(read, 1000);                            // the open chunk is lost...
    EXPECT_LE(uint64_t(1000 - read) * 40, 4u << 10);  // ...and nothing more
  }
  fs::remove(p);
  fs::remove(copy);
}

TEST(Recorder, CamerasGoIntoFoxgloveChannelsAtTheirRate) {
  auto camera = [](uint8_t shade) {
    engine::DataPack dp;
    dp.mutable_id()->set_name("cam");
    dp.mutable_id()->set_engine_name("eng");
    datapack::InlineBlobWriter writer;
    datapack::Builder b(&dp, writer);
    datapack::write_camera(b, 24, 32, 3, std::string(24 * 32 * 3, static_cast<char>(shade)));
    return dp;
  };
  for (const bool blobs : {false, true}) {
    const fs::path p = temp_file(blobs ? "rec_blobs.mcap" : "rec.mcap");
    {
      RecorderOptions options;
      options.camera_hz = 2;
      Recorder rec(p, blobs, {{"convoy_version", "test"}}, options);
      for (int i = 0; i <= 50; ++i)  // 1 s at 50 frames/s
        rec.from_engine("eng", camera(uint8_t(i)), datapack::inline_blob_reader(), i,
                        int64_t(i) * 20000000);
      EXPECT_EQ(rec.skipped(), 0u) << rec.first_skip();
      EXPECT_EQ(rec.finish({}), "");
    }
    McapReader r(p);
    McapMessage m;
    std::map<std::string, int> counts;
    nlohmann::json image, calibration;
    while (r.next(&m)) {
      const McapChannel& ch = r.channels().at(m.channel);
      ++counts[ch.topic];
      if (ch.topic == "eng/cam/image") image = nlohmann::json::parse(m.data);
      if (ch.topic == "eng/cam/calibration") calibration = nlohmann::json::parse(m.data);
    }
    EXPECT_TRUE(r.complete());
    EXPECT_EQ(counts["eng/cam"], 51);
    // 2 frames per simulated second without blobs (0, 0.5 s, 1 s), every one with them.
    EXPECT_EQ(counts["eng/cam/image"], blobs ? 51 : 3);
    EXPECT_EQ(counts["eng/cam/calibration"], counts["eng/cam/image"]);
    auto schema_of = [&](const std::string& topic) {
      for (const auto& [id, ch] : r.channels())
        if (ch.topic == topic) return r.schemas().at(ch.schema_id).name;
      return std::string();
    };
    EXPECT_EQ(schema_of("eng/cam/image"), "foxglove.CompressedImage");
    EXPECT_EQ(schema_of("eng/cam/calibration"), "foxglove.CameraCalibration");
    EXPECT_EQ(image["format"], "jpeg");
    EXPECT_EQ(image["frame_id"], "eng/cam");
    const std::string jpeg = base64_decode(image["data"].get<std::string>());
    ASSERT_GT(jpeg.size(), 4u);
    EXPECT_EQ(jpeg.substr(0, 3), "\xff\xd8\xff");
    EXPECT_EQ(calibration["width"], 32);
    EXPECT_EQ(calibration["height"], 24);
    EXPECT_EQ(calibration["K"].size(), 9u);
    fs::remove(p);
  }
}
