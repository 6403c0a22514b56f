#include "record/mcap_writer.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace convoy::record {

namespace mcap_io {

void put_u8(std::string* out, uint8_t v) { out->push_back(static_cast<char>(v)); }
void put_u16(std::string* out, uint16_t v) {
  for (int i = 0; i < 2; ++i) out->push_back(static_cast<char>(v >> (8 * i)));
}
void put_u32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(v >> (8 * i)));
}
void put_u64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>(v >> (8 * i)));
}
void put_string(std::string* out, std::string_view s) {
  put_u32(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}
void put_map(std::string* out, const StringMap& map) {
  std::string body;
  for (const auto& [k, v] : map) {
    put_string(&body, k);
    put_string(&body, v);
  }
  put_string(out, body);
}
std::string record(uint8_t op, std::string_view content) {
  std::string out;
  out.reserve(9 + content.size());
  put_u8(&out, op);
  put_u64(&out, content.size());
  out.append(content);
  return out;
}
uint32_t crc32(std::string_view bytes, uint32_t crc) {
  // zlib takes a uInt length: feed large buffers in pieces.
  uLong c = crc;
  const auto* p = reinterpret_cast<const Bytef*>(bytes.data());
  size_t left = bytes.size();
  while (left > 0) {
    const uInt n = static_cast<uInt>(std::min<size_t>(left, 1u << 30));
    c = ::crc32(c, p, n);
    p += n;
    left -= n;
  }
  return static_cast<uint32_t>(c);
}

}  // namespace mcap_io

using namespace mcap_io;

// ZSTD_CCtx, opaque in the header so that it does not include zstd.h.
struct McapWriter::ZstdContext {
  ZSTD_CCtx* cctx = nullptr;
};
void McapWriter::ZstdContextDeleter::operator()(ZstdContext* c) const {
  ZSTD_freeCCtx(c->cctx);
  delete c;
}

McapWriter::~McapWriter() { close(); }

void McapWriter::open(const std::filesystem::path& path, const std::string& library,
                      const McapWriterOptions& options) {
  if (fd_ >= 0) throw std::logic_error("McapWriter: already open");
  path_ = path;
  options_ = options;
  if (options_.compression == McapCompression::kZstd && !zstd_) {
    zstd_.reset(new ZstdContext);
    zstd_->cctx = ZSTD_createCCtx();
    if (!zstd_->cctx) throw std::runtime_error(path.string() + ": cannot create a zstd context");
  }
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error("cannot create " + path.string() + ": " + std::strerror(errno));
  }
  std::string header;
  put_string(&header, "");  // profile
  put_string(&header, library);
  write_raw(kMcapMagic);
  write_raw(record(kOpHeader, header));
  commit();
  check_io();
}

void McapWriter::write_raw(std::string_view bytes) {
  if (fd_ < 0) return;
  pending_.append(bytes);
  data_crc_ = crc32(bytes, data_crc_);
  pos_ += bytes.size();
}

bool McapWriter::commit() {
  if (fd_ < 0 || io_error_) {
    pending_.clear();
    return false;
  }
  size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int err = n < 0 ? errno : EIO;
    io_error_ = true;
    error_ = err == ENOSPC || err == EDQUOT
                 ? "no space left writing " + path_.string()
                 : "cannot write " + path_.string() + ": " + std::strerror(err);
    // A partial record would stand between the last whole one and anything written later:
    // the file ends at its last whole record instead (and gives the space back).
    if (::ftruncate(fd_, static_cast<off_t>(file_pos_)) != 0) error_ += " (and cannot cut it back)";
    pending_.clear();
    return false;
  }
  file_pos_ += pending_.size();
  pending_.clear();
  return true;
}

void McapWriter::check_io() {
  if (io_error_) throw std::runtime_error(error_);
}

uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                std::string_view data) {
  if (next_schema_ == 0) throw std::length_error(path_.string() + ": too many schemas");
  const uint16_t id = next_schema_++;
  std::string body;
  put_u16(&body, id);
  put_string(&body, name);
  put_string(&body, encoding);
  put_string(&body, data);  // uint32 length-prefixed bytes
  std::string rec = record(kOpSchema, body);
  chunk_ += rec;
  schema_records_.push_back(std::move(rec));
  return id;
}

uint16_t McapWriter::add_channel(const std::string& topic, const std::string& message_encoding,
                                 uint16_t schema_id, const StringMap& metadata) {
  if (next_channel_ > std::numeric_limits<uint16_t>::max())
    throw std::length_error(path_.string() + ": more than 65536 channels");
  const auto id = static_cast<uint16_t>(next_channel_++);
  std::string body;
  put_u16(&body, id);
  put_u16(&body, schema_id);
  put_string(&body, topic);
  put_string(&body, message_encoding);
  put_map(&body, metadata);
  std::string rec = record(kOpChannel, body);
  chunk_ += rec;
  channel_records_.push_back(std::move(rec));
  channel_counts_[id];
  return id;
}

void McapWriter::write_message(uint16_t channel, uint32_t sequence, uint64_t log_time,
                               uint64_t publish_time, std::string_view data) {
  if (fd_ < 0 || io_error_) return;
  if (!chunk_has_messages_) chunk_opened_ = std::chrono::steady_clock::now();
  chunk_index_[channel].emplace_back(log_time, chunk_.size());
  put_u8(&chunk_, kOpMessage);
  put_u64(&chunk_, 2 + 4 + 8 + 8 + data.size());
  put_u16(&chunk_, channel);
  put_u32(&chunk_, sequence);
  put_u64(&chunk_, log_time);
  put_u64(&chunk_, publish_time);
  chunk_.append(data);
  if (!chunk_has_messages_ || log_time < chunk_start_) chunk_start_ = log_time;
  if (!chunk_has_messages_ || log_time > chunk_end_) chunk_end_ = log_time;
  if (message_count_ == 0 || log_time < start_time_) start_time_ = log_time;
  if (message_count_ == 0 || log_time > end_time_) end_time_ = log_time;
  chunk_has_messages_ = true;
  ++chunk_messages_;
  ++message_count_;
  ++channel_counts_[channel];
  // Full, or open long enough: what a crash would lose is what the open chunk holds.
  if (chunk_.size() >= options_.chunk_bytes ||
      (options_.chunk_seconds > 0 &&
       std::chrono::duration<double>(std::chrono::steady_clock::now() - chunk_opened_).count() >=
           options_.chunk_seconds))
    flush_chunk();
}

std::string_view McapWriter::compressed_chunk(const char** compression) {
  *compression = "";
  if (options_.compression != McapCompression::kZstd) return chunk_;
  compressed_.resize(ZSTD_compressBound(chunk_.size()));
  const size_t n = ZSTD_compressCCtx(zstd_->cctx, compressed_.data(), compressed_.size(),
                                     chunk_.data(), chunk_.size(), options_.zstd_level);
  // Should zstd fail, or not help (JPEG frames), the chunk goes uncompressed: the
  // specification lets each chunk say how it is compressed.
  if (ZSTD_isError(n) || n >= chunk_.size()) return chunk_;
  compressed_.resize(n);
  *compression = "zstd";
  return compressed_;
}

void McapWriter::flush_chunk() {
  if (fd_ < 0 || chunk_.empty() || io_error_) return;
  const uint64_t chunk_offset = pos_;
  const char* compression = "";
  const std::string_view records = compressed_chunk(&compression);
  std::string head;
  put_u64(&head, chunk_has_messages_ ? chunk_start_ : 0);
  put_u64(&head, chunk_has_messages_ ? chunk_end_ : 0);
  put_u64(&head, chunk_.size());   // uncompressed_size
  put_u32(&head, crc32(chunk_));   // uncompressed_crc
  put_string(&head, compression);  // compression
  put_u64(&head, records.size());  // records length
  std::string prefix;
  put_u8(&prefix, kOpChunk);
  put_u64(&prefix, head.size() + records.size());
  write_raw(prefix);
  write_raw(head);
  write_raw(records);
  uncompressed_bytes_ += chunk_.size();
  const uint64_t chunk_length = pos_ - chunk_offset;

  // Message indexes, one per channel with messages in the chunk.
  const uint64_t index_start = pos_;
  std::map<uint16_t, uint64_t> index_offsets;
  for (const auto& [channel, entries] : chunk_index_) {
    std::string body;
    put_u16(&body, channel);
    put_u32(&body, static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [time, offset] : entries) {
      put_u64(&body, time);
      put_u64(&body, offset);
    }
    index_offsets[channel] = pos_;
    write_raw(record(kOpMessageIndex, body));
  }

  std::string ci;
  put_u64(&ci, chunk_has_messages_ ? chunk_start_ : 0);
  put_u64(&ci, chunk_has_messages_ ? chunk_end_ : 0);
  put_u64(&ci, chunk_offset);
  put_u64(&ci, chunk_length);
  std::string offsets;
  for (const auto& [channel, offset] : index_offsets) {
    put_u16(&offsets, channel);
    put_u64(&offsets, offset);
  }
  put_string(&ci, offsets);
  put_u64(&ci, pos_ - index_start);
  put_string(&ci, compression);
  put_u64(&ci, records.size());  // compressed_size
  put_u64(&ci, chunk_.size());   // uncompressed_size
  keep_chunk_index(record(kOpChunkIndex, ci));

  ++chunk_count_;
  // The chunk and its message indexes in one write: in the kernel's hands from now on.
  if (commit()) file_messages_ += chunk_messages_;
  chunk_.clear();
  chunk_index_.clear();
  chunk_has_messages_ = false;
  chunk_messages_ = 0;
}

void McapWriter::keep_chunk_index(std::string rec) {
  if (!chunk_index_spill_ && !chunk_index_spill_failed_) {
    chunk_index_spill_.reset(std::tmpfile());  // unlinked at once: nothing left by a crash
    chunk_index_spill_failed_ = !chunk_index_spill_;
  }
  if (chunk_index_spill_ && chunk_index_records_.empty()) {
    if (std::fwrite(rec.data(), 1, rec.size(), chunk_index_spill_.get()) == rec.size()) {
      chunk_index_spilled_ += rec.size();
      return;
    }
    // The file takes no more (a full /tmp): what it holds up to here stays valid, the rest is
    // kept in memory.
  }
  chunk_index_records_.push_back(std::move(rec));
}

void McapWriter::put_summary(std::string_view bytes) {
  constexpr size_t kBlock = 1 << 20;
  pending_.append(bytes);
  summary_crc_ = crc32(bytes, summary_crc_);
  pos_ += bytes.size();
  if (pending_.size() >= kBlock) commit();
}

void McapWriter::put_summary_group(uint8_t op, const std::vector<std::string>& records) {
  if (records.empty()) return;
  const uint64_t start = pos_;
  for (const auto& r : records) put_summary(r);
  summary_groups_.emplace_back(op, start, pos_ - start);
}

// Every chunk index kept, in the order written (the spilled ones, then any kept in memory).
void McapWriter::put_chunk_indexes() {
  const uint64_t start = pos_;
  if (std::FILE* f = chunk_index_spill_.get(); f && chunk_index_spilled_ > 0) {
    std::fflush(f);
    std::rewind(f);
    std::string block(1 << 20, '\0');
    for (uint64_t left = chunk_index_spilled_; left > 0;) {
      const size_t n = std::fread(block.data(), 1, std::min<uint64_t>(left, block.size()), f);
      if (n == 0) break;
      put_summary(std::string_view(block.data(), n));
      left -= n;
    }
  }
  for (const auto& r : chunk_index_records_) put_summary(r);
  if (pos_ > start) summary_groups_.emplace_back(kOpChunkIndex, start, pos_ - start);
}

void McapWriter::write_metadata(const std::string& name, const StringMap& metadata) {
  if (fd_ < 0) return;
  flush_chunk();
  std::string body;
  put_string(&body, name);
  put_map(&body, metadata);
  const uint64_t offset = pos_;
  std::string rec = record(kOpMetadata, body);
  write_raw(rec);
  std::string index;
  put_u64(&index, offset);
  put_u64(&index, rec.size());
  put_string(&index, name);
  metadata_index_records_.push_back(record(kOpMetadataIndex, index));
  ++metadata_count_;
  commit();
}

std::string McapWriter::close() {
  if (fd_ < 0) return "";
  flush_chunk();
  if (io_error_) {  // the file stays as it was cut: no summary after a lost chunk
    ::close(fd_);
    fd_ = -1;
    return error_;
  }
  commit();
  const uint64_t cut_back = file_pos_;  // where the file ends if the summary cannot be written
  std::string data_end;
  put_u32(&data_end, data_crc_);
  write_raw(record(kOpDataEnd, data_end));

  // Summary, grouped by opcode; everything after Data End goes into the summary CRC.
  const uint64_t summary_start = pos_;
  summary_crc_ = 0;
  summary_groups_.clear();
  put_summary_group(kOpSchema, schema_records_);
  put_summary_group(kOpChannel, channel_records_);
  std::string stats;
  put_u64(&stats, message_count_);
  put_u16(&stats, static_cast<uint16_t>(schema_records_.size()));
  put_u32(&stats, static_cast<uint32_t>(channel_records_.size()));
  put_u32(&stats, 0);  // attachments
  put_u32(&stats, metadata_count_);
  put_u32(&stats, chunk_count_);
  put_u64(&stats, message_count_ ? start_time_ : 0);
  put_u64(&stats, message_count_ ? end_time_ : 0);
  std::string counts;
  for (const auto& [channel, n] : channel_counts_) {
    put_u16(&counts, channel);
    put_u64(&counts, n);
  }
  put_string(&stats, counts);
  put_summary_group(kOpStatistics, {record(kOpStatistics, stats)});
  put_chunk_indexes();
  put_summary_group(kOpMetadataIndex, metadata_index_records_);
  const uint64_t offsets_start = pos_;
  for (const auto& [op, start, length] : summary_groups_) {
    std::string so;
    put_u8(&so, op);
    put_u64(&so, start);
    put_u64(&so, length);
    put_summary(record(kOpSummaryOffset, so));
  }
  std::string footer_head;
  put_u8(&footer_head, kOpFooter);
  put_u64(&footer_head, 8 + 8 + 4);
  put_u64(&footer_head, summary_start);
  put_u64(&footer_head, offsets_start);
  put_summary(footer_head);
  std::string tail;
  put_u32(&tail, summary_crc_);
  tail.append(kMcapMagic);
  pending_ += tail;
  pos_ += tail.size();
  // A summary cut short would not be one: the file then ends at its last chunk, as a cut
  // recording does.
  if (!commit() && ::ftruncate(fd_, static_cast<off_t>(cut_back)) != 0)
    error_ += " (and cannot cut it back)";
  if (::close(fd_) != 0 && !io_error_) {
    io_error_ = true;
    error_ = "cannot write " + path_.string() + ": " + std::strerror(errno);
  }
  fd_ = -1;
  return error_;
}

}  // namespace convoy::record
