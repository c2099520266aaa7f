// An MCAP file writer (https://mcap.dev/spec, version 0): schemas, channels and messages in compressed chunks,
// each chunk followed by its message indexes, and at Close a summary (schemas, channels, statistics, chunk index)
// with summary offsets and the footer, so indexed readers seek and stream readers read straight through.
// Chunks are written out as they fill (and on Flush), so a file whose writer was killed keeps every chunk that
// was closed before: a stream reader reads them and stops at the truncation.
// Written to the spec, not from a library: the C++ MCAP library is not in Debian, and the format is small.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace graspsim::recording {

enum class Compression { kNone, kZstd, kLz4 };
// "zstd", "lz4", "none" or "" (zstd); throws Error(kInvalidArgument) naming `field` otherwise.
Compression ParseCompression(const std::string& text, const std::string& field);

struct McapOptions {
  std::string profile;                  // "" for our own profile, "ros2" for ROS 2 bags
  Compression compression = Compression::kZstd;
  size_t chunk_bytes = 512 * 1024;      // uncompressed records per chunk before it is written out
};

class McapWriter {
 public:
  // Creates (truncates) `path`; throws Error(kFailedPrecondition) naming it when it cannot.
  McapWriter(const std::string& path, McapOptions options);
  ~McapWriter();  // Close()
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids start at 1. A schema or channel is written into the data before the first message that uses it.
  uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                      const std::map<std::string, std::string>& metadata = {});
  // Times in ns. Throws Error(kInternal) when the file cannot be written (disk full).
  void Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data);
  // Writes the open chunk out (a reader of the file so far sees it).
  void Flush();
  // Writes the summary and footer and closes the file; idempotent.
  void Close();

  uint64_t bytes_written() const { return file_offset_; }
  uint64_t message_count() const { return message_count_; }

 private:
  struct ChunkIndexEntry {
    uint64_t start_time, end_time, chunk_offset, chunk_length, index_length;
    std::map<uint16_t, uint64_t> index_offsets;
    uint64_t compressed_size, uncompressed_size;
  };
  struct SchemaRecord { uint16_t id; std::string name, encoding, data; };
  struct ChannelRecord {
    uint16_t id, schema_id;
    std::string topic, encoding;
    std::map<std::string, std::string> metadata;
  };

  void WriteOut(const std::string& bytes);
  void CloseChunk();

  std::string path_;
  McapOptions options_;
  std::FILE* file_ = nullptr;
  uint64_t file_offset_ = 0;
  std::vector<SchemaRecord> schemas_;
  std::vector<ChannelRecord> channels_;
  std::string chunk_;  // uncompressed records of the open chunk
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_;  // channel -> (log time, offset)
  uint64_t chunk_start_time_ = UINT64_MAX, chunk_end_time_ = 0;
  std::vector<ChunkIndexEntry> chunk_indexes_;
  std::map<uint16_t, uint64_t> channel_counts_;
  std::map<uint16_t, uint32_t> sequence_;
  uint64_t message_count_ = 0, first_time_ = UINT64_MAX, last_time_ = 0;
};

}  // namespace graspsim::recording
