// An MCAP file writer (https://mcap.dev/spec), written from the specification: the log
// format of ROS 2 and Foxglove, which Foxglove and Lichtblick open.
//
// Layout: magic, Header, then the data section: Chunks (Schema, Channel and Message records,
// compressed with zstd unless asked otherwise) each followed by its Message Index records,
// Metadata records between chunks; Data End; a Summary section (Schemas, Channels,
// Statistics, Chunk Indexes, Metadata Indexes, grouped by opcode), Summary Offsets, Footer,
// magic. CRC32s (zlib) everywhere the format has one; a chunk's CRC is that of its
// uncompressed records, as the specification asks.
//
// The file is written as it goes: a chunk goes to the kernel (one write(2), no stdio buffer)
// once its records hold about `chunk_bytes` (uncompressed) or once it has been open for
// `chunk_seconds` of wall time, so memory stays bounded and a killed process leaves every
// finished chunk readable by a streaming reader: it loses the open chunk only (at most about a
// second of the run). close() writes the summary and footer.
//
// A write that fails (no space left, quota, I/O error) is not thrown from write_message():
// the writer stops writing, cuts the file back to the end of its last whole record (so the
// file stays a readable prefix and the space of the partial chunk is given back), and says
// why in error(); the owner checks error() and ends the run.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace convoy::record {

inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

enum McapOp : uint8_t {
  kOpHeader = 0x01,
  kOpFooter = 0x02,
  kOpSchema = 0x03,
  kOpChannel = 0x04,
  kOpMessage = 0x05,
  kOpChunk = 0x06,
  kOpMessageIndex = 0x07,
  kOpChunkIndex = 0x08,
  kOpAttachment = 0x09,
  kOpAttachmentIndex = 0x0A,
  kOpStatistics = 0x0B,
  kOpMetadata = 0x0C,
  kOpMetadataIndex = 0x0D,
  kOpSummaryOffset = 0x0E,
  kOpDataEnd = 0x0F,
};

using StringMap = std::map<std::string, std::string>;

// How a chunk's records are compressed (the Chunk's `compression` field: "" or "zstd").
enum class McapCompression { kNone, kZstd };

struct McapWriterOptions {
  size_t chunk_bytes = size_t{1} << 20;  // uncompressed records per chunk, about
  McapCompression compression = McapCompression::kZstd;
  int zstd_level = 3;          // zstd's default: ~10x on Convoy's JSON for little CPU
  double chunk_seconds = 1.0;  // wall time a chunk with messages stays open, at most (0: any)
};

class McapWriter {
 public:
  McapWriter() = default;
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Creates (truncates) `path` and writes the magic and the Header (profile "", `library`).
  // Throws std::runtime_error naming the file.
  void open(const std::filesystem::path& path, const std::string& library,
            const McapWriterOptions& options = {});
  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }

  // A schema (id from 1). Written into the current chunk and the summary.
  uint16_t add_schema(const std::string& name, const std::string& encoding, std::string_view data);
  // A channel (id from 0); schema_id 0: none. Throws std::length_error past 65535 channels.
  uint16_t add_channel(const std::string& topic, const std::string& message_encoding,
                       uint16_t schema_id, const StringMap& metadata);
  void write_message(uint16_t channel, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                     std::string_view data);
  // A Metadata record (between chunks: the current chunk is written first).
  void write_metadata(const std::string& name, const StringMap& metadata);

  // Finishes the file: the last chunk, Data End, summary, footer, magic. Never throws (a
  // write error is returned, "" when all went well). Idempotent. After a write error the
  // file is left as it was cut (no summary): a prefix that readers read up to its end.
  std::string close();

  // The first write error ("no space left writing PATH", "cannot write PATH: ..."), or "".
  const std::string& error() const { return error_; }

  uint64_t message_count() const { return message_count_; }
  uint64_t bytes_written() const { return pos_; }
  // What the file holds: bytes, and messages in whole chunks (less than the above after a
  // write error, or before close()).
  uint64_t file_bytes() const { return file_pos_; }
  uint64_t file_messages() const { return file_messages_; }
  // The chunks' records before compression (what an uncompressed file would hold).
  uint64_t uncompressed_chunk_bytes() const { return uncompressed_bytes_; }

 private:
  void write_raw(std::string_view bytes);  // to the data section (counts its CRC)
  // Writes what write_raw() gathered to the file; on failure, cuts the file back and sets
  // error_. True when written.
  bool commit();
  void flush_chunk();
  void check_io();
  // The chunk's records as the file holds them, and their `compression` ("zstd" or "").
  std::string_view compressed_chunk(const char** compression);

  struct ZstdContext;
  struct ZstdContextDeleter {
    void operator()(ZstdContext* c) const;
  };

  std::filesystem::path path_;
  int fd_ = -1;
  bool io_error_ = false;
  std::string error_;
  std::string pending_;  // gathered by write_raw(), written by commit()
  uint64_t pos_ = 0;     // where the next record goes (as if every write succeeded)
  uint64_t file_pos_ = 0, file_messages_ = 0;  // what the file holds
  uint32_t data_crc_ = 0;
  McapWriterOptions options_;
  std::unique_ptr<ZstdContext, ZstdContextDeleter> zstd_;
  std::string compressed_;
  uint64_t uncompressed_bytes_ = 0;

  // The chunk being filled.
  std::string chunk_;
  uint64_t chunk_start_ = 0, chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  uint64_t chunk_messages_ = 0;
  std::chrono::steady_clock::time_point chunk_opened_;  // its first message
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_;

  // For the summary. The chunk indexes (one per chunk, about 1.5 KB with a hundred channels)
  // wait in an unlinked temporary file, so that the writer's memory stays flat over a long run
  // (in memory if no temporary file can be made).
  void keep_chunk_index(std::string record);
  // The summary, written in blocks (an hour's chunk indexes are megabytes: never all in memory
  // at once). put_summary appends to it, adding to summary_crc_.
  void put_summary(std::string_view bytes);
  void put_summary_group(uint8_t op, const std::vector<std::string>& records);
  void put_chunk_indexes();
  uint32_t summary_crc_ = 0;
  std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> summary_groups_;  // op, start, length
  std::vector<std::string> schema_records_, channel_records_, chunk_index_records_,
      metadata_index_records_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> chunk_index_spill_{nullptr, &std::fclose};
  bool chunk_index_spill_failed_ = false;
  uint64_t chunk_index_spilled_ = 0;  // bytes in the file
  std::map<uint16_t, uint64_t> channel_counts_;
  uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  uint32_t chunk_count_ = 0, metadata_count_ = 0;
  uint16_t next_schema_ = 1;
  uint32_t next_channel_ = 0;
};

// Serialization helpers (little-endian), shared with the tests.
namespace mcap_io {
void put_u8(std::string* out, uint8_t v);
void put_u16(std::string* out, uint16_t v);
void put_u32(std::string* out, uint32_t v);
void put_u64(std::string* out, uint64_t v);
void put_string(std::string* out, std::string_view s);  // u32 length + bytes
void put_map(std::string* out, const StringMap& map);
// <op><u64 length><content>
std::string record(uint8_t op, std::string_view content);
uint32_t crc32(std::string_view bytes, uint32_t crc = 0);
}  // namespace mcap_io

}  // namespace convoy::record
