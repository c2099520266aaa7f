#include "recording/mcap_writer.h"

#include <cstring>
#include <filesystem>
#include <functional>
#include <tuple>

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include "core/durable_files.h"
#include "core/error.h"

namespace graspsim::recording {
namespace {

constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
enum Opcode : uint8_t {
  kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
  kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B, kSummaryOffset = 0x0E, kDataEnd = 0x0F,
};

// Little-endian field encoders of the spec's primitive types.
void U8(std::string* out, uint8_t v) { out->push_back(static_cast<char>(v)); }
template <typename T>
void Int(std::string* out, T v) {
  for (size_t i = 0; i < sizeof(T); ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void Str(std::string* out, std::string_view s) {
  Int<uint32_t>(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}
void Record(std::string* out, uint8_t opcode, const std::string& body) {
  U8(out, opcode);
  Int<uint64_t>(out, body.size());
  out->append(body);
}
uint32_t Crc32(std::string_view bytes, uint32_t crc = 0) {
  return static_cast<uint32_t>(::crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()),
                                       static_cast<uInt>(bytes.size())));
}
const char* CompressionName(Compression c) {
  return c == Compression::kZstd ? "zstd" : c == Compression::kLz4 ? "lz4" : "";
}
std::string Compress(Compression c, const std::string& in) {
  std::string out;
  if (c == Compression::kZstd) {
    out.resize(ZSTD_compressBound(in.size()));
    // Level 1, zstd's fastest standard level: the writer thread shares the machine with the simulation.
    const size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 1);
    if (ZSTD_isError(n)) throw Error(ErrorCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
  } else if (c == Compression::kLz4) {  // MCAP's lz4 is the LZ4 frame format
    out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
    const size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
    if (LZ4F_isError(n)) throw Error(ErrorCode::kInternal, std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
  } else {
    out = in;
  }
  return out;
}
std::string SchemaBody(uint16_t id, const std::string& name, const std::string& encoding, const std::string& data) {
  std::string body;
  Int<uint16_t>(&body, id);
  Str(&body, name);
  Str(&body, encoding);
  Str(&body, data);
  return body;
}
std::string ChannelBody(uint16_t id, uint16_t schema_id, const std::string& topic, const std::string& encoding,
                        const std::map<std::string, std::string>& metadata) {
  std::string body, map;
  Int<uint16_t>(&body, id);
  Int<uint16_t>(&body, schema_id);
  Str(&body, topic);
  Str(&body, encoding);
  for (const auto& [key, value] : metadata) {
    Str(&map, key);
    Str(&map, value);
  }
  Str(&body, map);
  return body;
}

}  // namespace

Compression ParseCompression(const std::string& text, const std::string& field) {
  if (text.empty() || text == "zstd") return Compression::kZstd;
  if (text == "lz4") return Compression::kLz4;
  if (text == "none") return Compression::kNone;
  ThrowInvalidArgument(field + ": '" + text + "' is not a compression; give zstd, lz4 or none");
}

McapWriter::McapWriter(const std::string& path, McapOptions options) : path_(path), options_(std::move(options)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) {
    throw Error(ErrorCode::kFailedPrecondition, "cannot create '" + path + "': " + std::strerror(errno));
  }
  std::string head(kMagic, sizeof(kMagic)), header;
  Str(&header, options_.profile);
  Str(&header, "graspsim");
  Record(&head, kHeader, header);
  WriteOut(head);
  std::fflush(file_);  // a reader of a recording in progress sees an MCAP file from the start
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const Error&) {  // a destructor cannot report; Close() called explicitly does
  }
}

void McapWriter::WriteOut(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw Error(ErrorCode::kInternal, "cannot write '" + path_ + "': " + std::strerror(errno));
  }
  file_offset_ += bytes.size();
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  const auto id = static_cast<uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, name, encoding, data});
  Record(&chunk_, kSchema, SchemaBody(id, name, encoding, data));
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                const std::map<std::string, std::string>& metadata) {
  const auto id = static_cast<uint16_t>(channels_.size() + 1);
  channels_.push_back({id, schema_id, topic, message_encoding, metadata});
  Record(&chunk_, kChannel, ChannelBody(id, schema_id, topic, message_encoding, metadata));
  return id;
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data) {
  if (!file_) throw Error(ErrorCode::kInternal, "'" + path_ + "' is closed");
  chunk_index_[channel_id].emplace_back(log_time, chunk_.size());
  // The record written in place (no intermediate body: a message is copied once).
  U8(&chunk_, kMessage);
  Int<uint64_t>(&chunk_, 2 + 4 + 8 + 8 + data.size());
  Int<uint16_t>(&chunk_, channel_id);
  Int<uint32_t>(&chunk_, sequence_[channel_id]++);
  Int<uint64_t>(&chunk_, log_time);
  Int<uint64_t>(&chunk_, publish_time);
  chunk_.append(data);
  chunk_start_time_ = std::min(chunk_start_time_, log_time);
  chunk_end_time_ = std::max(chunk_end_time_, log_time);
  first_time_ = std::min(first_time_, log_time);
  last_time_ = std::max(last_time_, log_time);
  ++channel_counts_[channel_id];
  ++message_count_;
  if (chunk_.size() >= options_.chunk_bytes) CloseChunk();
}

void McapWriter::CloseChunk() {
  if (chunk_.empty()) return;
  const bool has_messages = !chunk_index_.empty();
  const std::string compressed = Compress(options_.compression, chunk_);
  const std::string_view compression = CompressionName(options_.compression);
  std::string out;  // the chunk record written in place (the compressed bytes are copied once)
  U8(&out, kChunk);
  Int<uint64_t>(&out, 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + compressed.size());
  Int<uint64_t>(&out, has_messages ? chunk_start_time_ : 0);
  Int<uint64_t>(&out, has_messages ? chunk_end_time_ : 0);
  Int<uint64_t>(&out, chunk_.size());
  Int<uint32_t>(&out, Crc32(chunk_));
  Str(&out, compression);
  Int<uint64_t>(&out, compressed.size());
  out.append(compressed);
  ChunkIndexEntry entry{has_messages ? chunk_start_time_ : 0, has_messages ? chunk_end_time_ : 0, file_offset_,
                        out.size(), 0, {}, compressed.size(), chunk_.size()};
  for (const auto& [channel, entries] : chunk_index_) {
    std::string index, pairs;
    Int<uint16_t>(&index, channel);
    for (const auto& [time, offset] : entries) {
      Int<uint64_t>(&pairs, time);
      Int<uint64_t>(&pairs, offset);
    }
    Str(&index, pairs);
    entry.index_offsets[channel] = file_offset_ + out.size();
    const size_t before = out.size();
    Record(&out, kMessageIndex, index);
    entry.index_length += out.size() - before;
  }
  WriteOut(out);
  if (std::fflush(file_) != 0) throw Error(ErrorCode::kInternal, "cannot write '" + path_ + "'");
  chunk_indexes_.push_back(std::move(entry));
  chunk_.clear();
  chunk_index_.clear();
  chunk_start_time_ = UINT64_MAX;
  chunk_end_time_ = 0;
}

void McapWriter::Flush() {
  if (!file_) return;
  CloseChunk();
}

void McapWriter::Close() {
  if (!file_) return;
  CloseChunk();
  std::string out;
  std::string data_end;
  Int<uint32_t>(&data_end, 0);  // 0: the data section's CRC is not computed (allowed by the spec)
  Record(&out, kDataEnd, data_end);
  WriteOut(out);
  out.clear();

  // Summary: one group per record kind, each located by a summary offset record.
  const uint64_t summary_start = file_offset_;
  std::string summary;
  std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> groups;  // opcode, start, length
  auto group = [&](uint8_t opcode, const std::function<void()>& write) {
    const uint64_t start = summary.size();
    write();
    if (summary.size() > start) groups.emplace_back(opcode, summary_start + start, summary.size() - start);
  };
  group(kSchema, [&] {
    for (const auto& s : schemas_) Record(&summary, kSchema, SchemaBody(s.id, s.name, s.encoding, s.data));
  });
  group(kChannel, [&] {
    for (const auto& c : channels_) Record(&summary, kChannel, ChannelBody(c.id, c.schema_id, c.topic, c.encoding, c.metadata));
  });
  group(kStatistics, [&] {
    std::string body, counts;
    Int<uint64_t>(&body, message_count_);
    Int<uint16_t>(&body, static_cast<uint16_t>(schemas_.size()));
    Int<uint32_t>(&body, static_cast<uint32_t>(channels_.size()));
    Int<uint32_t>(&body, 0);  // attachments
    Int<uint32_t>(&body, 0);  // metadata records
    Int<uint32_t>(&body, static_cast<uint32_t>(chunk_indexes_.size()));
    Int<uint64_t>(&body, message_count_ ? first_time_ : 0);
    Int<uint64_t>(&body, message_count_ ? last_time_ : 0);
    for (const auto& [channel, count] : channel_counts_) {
      Int<uint16_t>(&counts, channel);
      Int<uint64_t>(&counts, count);
    }
    Str(&body, counts);
    Record(&summary, kStatistics, body);
  });
  group(kChunkIndex, [&] {
    for (const auto& c : chunk_indexes_) {
      std::string body, offsets;
      Int<uint64_t>(&body, c.start_time);
      Int<uint64_t>(&body, c.end_time);
      Int<uint64_t>(&body, c.chunk_offset);
      Int<uint64_t>(&body, c.chunk_length);
      for (const auto& [channel, offset] : c.index_offsets) {
        Int<uint16_t>(&offsets, channel);
        Int<uint64_t>(&offsets, offset);
      }
      Str(&body, offsets);
      Int<uint64_t>(&body, c.index_length);
      Str(&body, CompressionName(options_.compression));
      Int<uint64_t>(&body, c.compressed_size);
      Int<uint64_t>(&body, c.uncompressed_size);
      Record(&summary, kChunkIndex, body);
    }
  });
  const uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& [opcode, start, length] : groups) {
    std::string body;
    U8(&body, opcode);
    Int<uint64_t>(&body, start);
    Int<uint64_t>(&body, length);
    Record(&summary, kSummaryOffset, body);
  }
  // The footer's CRC covers the summary and the footer's fields before it.
  std::string footer;
  U8(&footer, kFooter);
  Int<uint64_t>(&footer, 8 + 8 + 4);
  Int<uint64_t>(&footer, summary_start);
  Int<uint64_t>(&footer, summary_offset_start);
  const uint32_t crc = Crc32(footer, Crc32(summary));
  Int<uint32_t>(&footer, crc);
  summary += footer;
  summary.append(kMagic, sizeof(kMagic));
  WriteOut(summary);
  // A finished recording survives a power cut: its bytes synced, then its name in the directory
  // (tests/python/test_power_cut_shim.py).
  try {
    SyncFile(file_, path_);
  } catch (const Error&) {
    std::fclose(file_);
    file_ = nullptr;
    throw;
  }
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!closed) throw Error(ErrorCode::kInternal, "cannot close '" + path_ + "'");
  const std::filesystem::path directory = std::filesystem::absolute(path_).parent_path();
  if (!SyncDirectory(directory)) {
    throw Error(ErrorCode::kInternal, "cannot sync the directory of '" + path_ + "': " + std::strerror(errno));
  }
}

}  // namespace graspsim::recording
