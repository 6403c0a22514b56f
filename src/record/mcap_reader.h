// Reads MCAP files (https://mcap.dev/spec) written by McapWriter or anyone else, front to
// back: the records of the data section, with the records inside chunks (uncompressed or
// compressed with zstd) in their place. Checks the magic, every record's length, the chunks'
// CRCs, the data section's CRC and the summary's CRC. A file cut short (a killed writer) reads
// up to its last whole record; whether it ended cleanly is reported, not thrown.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "record/mcap_writer.h"

namespace convoy::record {

// A malformed file: what() names the file and the byte offset.
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct McapSchema {
  uint16_t id = 0;
  std::string name, encoding, data;
};
struct McapChannel {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  StringMap metadata;
};
struct McapMessage {
  uint16_t channel = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;
  std::string data;
};

class McapReader {
 public:
  // Opens the file and reads its magic and Header. Throws McapError.
  explicit McapReader(const std::filesystem::path& path);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  // The next message of the data section (schemas, channels and metadata met on the way are
  // kept below). False at the end of the data section, or of a file cut short (see
  // complete()). Throws McapError on a malformed record or a CRC that does not match.
  bool next(McapMessage* message);
  // Reads to the end of the data section, then the summary and footer (checking the CRCs).
  void read_to_end();

  // After the end: whether the file had its Data End, summary and footer (a finished file),
  // and why not.
  bool complete() const { return complete_; }
  const std::string& incomplete_reason() const { return incomplete_; }

  const std::map<uint16_t, McapSchema>& schemas() const { return schemas_; }
  const std::map<uint16_t, McapChannel>& channels() const { return channels_; }
  const std::map<std::string, StringMap>& metadata() const { return metadata_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  bool read_exact(std::string* out, uint64_t n);
  [[noreturn]] void fail(const std::string& what, uint64_t offset) const;
  void parse_record(uint8_t op, std::string_view body, uint64_t offset, bool in_chunk,
                    McapMessage* message, bool* got_message);
  void finish_file(uint64_t data_end_offset, std::string_view data_end_body);

  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  uint64_t pos_ = 0;
  uint32_t data_crc_ = 0;
  bool at_end_ = false, complete_ = false;
  std::string incomplete_;
  std::string profile_, library_;
  std::map<uint16_t, McapSchema> schemas_;
  std::map<uint16_t, McapChannel> channels_;
  std::map<std::string, StringMap> metadata_;
  // The chunk being read.
  std::string chunk_;
  size_t chunk_pos_ = 0;
  uint64_t chunk_offset_ = 0;
};

}  // namespace convoy::record
