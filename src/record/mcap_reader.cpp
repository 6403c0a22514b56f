#include "record/mcap_reader.h"

#include <zstd.h>

#include <cerrno>
#include <cstring>

namespace convoy::record {

namespace {

// Reads fields of one record's content; false past its end.
struct Cursor {
  std::string_view s;
  size_t p = 0;
  bool ok = true;
  uint64_t uint(int bytes) {
    if (!ok || s.size() - p < static_cast<size_t>(bytes)) {
      ok = false;
      return 0;
    }
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i)
      v |= static_cast<uint64_t>(static_cast<uint8_t>(s[p + i])) << (8 * i);
    p += bytes;
    return v;
  }
  std::string_view bytes(uint64_t n) {
    if (!ok || s.size() - p < n) {
      ok = false;
      return {};
    }
    std::string_view out = s.substr(p, n);
    p += n;
    return out;
  }
  std::string string() { return std::string(bytes(uint(4))); }
  StringMap map() {
    StringMap out;
    Cursor inner{bytes(uint(4))};
    while (ok && inner.ok && inner.p < inner.s.size()) {
      std::string k = inner.string();
      out[k] = inner.string();
    }
    ok = ok && inner.ok;
    return out;
  }
};

}  // namespace

McapReader::McapReader(const std::filesystem::path& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw McapError(path.string() + ": cannot open: " + std::strerror(errno));
  std::string magic;
  if (!read_exact(&magic, kMcapMagic.size()) || magic != kMcapMagic)
    fail("not an MCAP file (no MCAP magic at the start)", 0);
  data_crc_ = mcap_io::crc32(magic);
  std::string head;
  if (!read_exact(&head, 9) || head[0] != kOpHeader) fail("no Header record after the magic", 8);
  Cursor c{head.substr(1)};
  const uint64_t len = c.uint(8);
  std::string body;
  if (len > (uint64_t{1} << 30) || !read_exact(&body, len)) fail("Header record cut short", 8);
  data_crc_ = mcap_io::crc32(body, mcap_io::crc32(head, data_crc_));
  Cursor h{body};
  profile_ = h.string();
  library_ = h.string();
  if (!h.ok) fail("malformed Header record", 8);
}

McapReader::~McapReader() {
  if (file_) std::fclose(file_);
}

bool McapReader::read_exact(std::string* out, uint64_t n) {
  out->resize(n);
  const size_t got = n ? std::fread(out->data(), 1, n, file_) : 0;
  pos_ += got;
  if (got != n) {
    out->resize(got);
    return false;
  }
  return true;
}

void McapReader::fail(const std::string& what, uint64_t offset) const {
  throw McapError(path_.string() + ": " + what + " (at byte " + std::to_string(offset) + ")");
}

void McapReader::parse_record(uint8_t op, std::string_view body, uint64_t offset, bool in_chunk,
                              McapMessage* message, bool* got_message) {
  Cursor c{body};
  switch (op) {
    case kOpSchema: {
      McapSchema s;
      s.id = static_cast<uint16_t>(c.uint(2));
      s.name = c.string();
      s.encoding = c.string();
      s.data = std::string(c.bytes(c.uint(4)));
      if (!c.ok) fail("malformed Schema record", offset);
      if (s.id != 0) schemas_[s.id] = std::move(s);
      return;
    }
    case kOpChannel: {
      McapChannel ch;
      ch.id = static_cast<uint16_t>(c.uint(2));
      ch.schema_id = static_cast<uint16_t>(c.uint(2));
      ch.topic = c.string();
      ch.message_encoding = c.string();
      ch.metadata = c.map();
      if (!c.ok) fail("malformed Channel record", offset);
      if (ch.schema_id != 0 && !schemas_.count(ch.schema_id))
        fail("Channel '" + ch.topic + "' names schema " + std::to_string(ch.schema_id) +
                 ", not defined before it",
             offset);
      channels_[ch.id] = std::move(ch);
      return;
    }
    case kOpMessage: {
      message->channel = static_cast<uint16_t>(c.uint(2));
      message->sequence = static_cast<uint32_t>(c.uint(4));
      message->log_time = c.uint(8);
      message->publish_time = c.uint(8);
      if (!c.ok) fail("malformed Message record", offset);
      if (!channels_.count(message->channel))
        fail("Message on channel " + std::to_string(message->channel) + ", not defined before it",
             offset);
      message->data.assign(body.substr(c.p));
      *got_message = true;
      return;
    }
    case kOpMetadata: {
      std::string name = c.string();
      StringMap m = c.map();
      if (!c.ok) fail("malformed Metadata record", offset);
      metadata_[name] = std::move(m);
      return;
    }
    case kOpChunk: {
      if (in_chunk) fail("Chunk inside a chunk", offset);
      c.uint(8);
      c.uint(8);
      const uint64_t uncompressed_size = c.uint(8);
      const uint32_t crc = static_cast<uint32_t>(c.uint(4));
      const std::string compression = c.string();
      const std::string_view records = c.bytes(c.uint(8));
      if (!c.ok) fail("malformed Chunk record", offset);
      if (compression.empty()) {
        if (records.size() != uncompressed_size) fail("Chunk sizes disagree", offset);
        chunk_.assign(records);
      } else if (compression == "zstd") {
        // Bounded: a corrupt size must not make the reader ask for terabytes.
        if (uncompressed_size > (uint64_t{1} << 34))
          fail("Chunk says it holds " + std::to_string(uncompressed_size) + " bytes", offset);
        chunk_.resize(uncompressed_size);
        const size_t n =
            ZSTD_decompress(chunk_.data(), chunk_.size(), records.data(), records.size());
        if (ZSTD_isError(n))
          fail(std::string("zstd chunk does not decompress: ") + ZSTD_getErrorName(n), offset);
        if (n != uncompressed_size)
          fail("zstd chunk decompresses to " + std::to_string(n) + " bytes, not " +
                   std::to_string(uncompressed_size),
               offset);
      } else {
        fail("Chunk compressed with '" + compression + "' (only zstd and none are read)", offset);
      }
      if (crc != 0 && mcap_io::crc32(chunk_) != crc) fail("Chunk CRC does not match", offset);
      chunk_pos_ = 0;
      chunk_offset_ = offset;
      return;
    }
    default:
      return;  // indexes, attachments, unknown records: skipped
  }
}

bool McapReader::next(McapMessage* message) {
  while (true) {
    // Records inside the current chunk first.
    while (chunk_pos_ < chunk_.size()) {
      Cursor c{chunk_, chunk_pos_};
      const auto op = static_cast<uint8_t>(c.uint(1));
      const uint64_t len = c.uint(8);
      std::string_view body = c.bytes(len);
      if (!c.ok) fail("record cut short inside the chunk", chunk_offset_);
      chunk_pos_ = c.p;
      if (op == kOpChunk || op == kOpDataEnd || op == kOpFooter)
        fail("record " + std::to_string(op) + " inside a chunk", chunk_offset_);
      bool got = false;
      parse_record(op, body, chunk_offset_, /*in_chunk=*/true, message, &got);
      if (got) return true;
    }
    chunk_.clear();
    chunk_pos_ = 0;
    if (at_end_) return false;
    const uint64_t offset = pos_;
    std::string head;
    if (!read_exact(&head, 9)) {
      at_end_ = true;
      incomplete_ = head.empty() ? "it ends without its Data End record (the writer stopped)"
                                 : "it is cut short at byte " + std::to_string(pos_);
      return false;
    }
    const auto op = static_cast<uint8_t>(head[0]);
    Cursor hc{std::string_view(head).substr(1)};
    const uint64_t len = hc.uint(8);
    std::string body;
    if (len > (uint64_t{1} << 40) || !read_exact(&body, len)) {
      at_end_ = true;
      incomplete_ = "it is cut short at byte " + std::to_string(pos_) + " (a record of " +
                    std::to_string(len) + " bytes at byte " + std::to_string(offset) + ")";
      return false;
    }
    if (op == kOpDataEnd) {
      at_end_ = true;
      finish_file(offset, body);
      return false;
    }
    if (op == kOpFooter || op == kOpHeader)
      fail("unexpected record " + std::to_string(op) + " in the data section", offset);
    data_crc_ = mcap_io::crc32(body, mcap_io::crc32(head, data_crc_));
    bool got = false;
    parse_record(op, body, offset, /*in_chunk=*/false, message, &got);
    if (got) return true;
  }
}

void McapReader::finish_file(uint64_t data_end_offset, std::string_view data_end_body) {
  Cursor d{data_end_body};
  const auto crc = static_cast<uint32_t>(d.uint(4));
  if (!d.ok) fail("malformed Data End record", data_end_offset);
  if (crc != 0 && crc != data_crc_) fail("data section CRC does not match", data_end_offset);
  // The rest: summary, summary offsets, footer, magic.
  const uint64_t summary_start = pos_;
  std::string rest;
  char buf[1 << 16];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, file_)) > 0;) rest.append(buf, n);
  pos_ += rest.size();
  if (rest.size() < 8 + 29 || rest.substr(rest.size() - 8) != kMcapMagic) {
    incomplete_ = "it is cut short after its Data End record (no footer)";
    return;
  }
  const size_t footer_at = rest.size() - 8 - 29;
  Cursor f{std::string_view(rest).substr(footer_at)};
  const auto op = static_cast<uint8_t>(f.uint(1));
  const uint64_t len = f.uint(8);
  const uint64_t sum_start = f.uint(8);
  f.uint(8);
  const auto sum_crc = static_cast<uint32_t>(f.uint(4));
  if (op != kOpFooter || len != 20) fail("no Footer before the closing magic", pos_ - 8 - 29);
  if (sum_crc != 0) {
    const uint64_t from = sum_start ? sum_start : summary_start + footer_at;
    if (from < summary_start || from - summary_start > footer_at)
      fail("Footer's summary_start is out of range", pos_ - 8 - 29);
    std::string_view covered = std::string_view(rest).substr(
        from - summary_start, footer_at + 1 + 8 + 16 - (from - summary_start));
    if (mcap_io::crc32(covered) != sum_crc) fail("summary CRC does not match", sum_start);
  }
  // Summary records: schemas and channels are duplicates; nothing else is needed here.
  complete_ = true;
}

void McapReader::read_to_end() {
  McapMessage m;
  while (next(&m)) {
  }
}

}  // namespace convoy::record
