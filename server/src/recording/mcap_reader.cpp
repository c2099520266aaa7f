#include "recording/mcap_reader.h"

#include <cstring>
#include <fstream>
#include <map>

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include "core/error.h"

namespace graspsim::recording {
namespace {

[[noreturn]] void Corrupt(const std::string& label, const std::string& what) {
  throw Error(ErrorCode::kFailedPrecondition, "recording '" + label + "': " + what);
}

// A bounds-checked little-endian cursor over one record's body.
struct Cursor {
  std::string_view bytes;
  const std::string* path;
  template <typename T>
  T Int() {
    if (bytes.size() < sizeof(T)) Corrupt(*path, "a record is shorter than its fields");
    T v = 0;
    for (size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<uint8_t>(bytes[i])) << (8 * i);
    bytes.remove_prefix(sizeof(T));
    return v;
  }
  std::string_view Take(uint64_t n) {
    if (bytes.size() < n) Corrupt(*path, "a record is shorter than its fields");
    std::string_view out = bytes.substr(0, n);
    bytes.remove_prefix(n);
    return out;
  }
  std::string_view Str() { return Take(Int<uint32_t>()); }
};

std::string Decompress(const std::string& path, std::string_view compression, std::string_view data, uint64_t size) {
  if (size > (uint64_t{1} << 32)) Corrupt(path, "a chunk claims more than 4 GiB");
  std::string out(size, '\0');
  if (compression.empty()) {
    if (data.size() != size) Corrupt(path, "an uncompressed chunk's size does not match");
    return std::string(data);
  }
  if (compression == "zstd") {
    const size_t n = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(n) || n != size) Corrupt(path, "a zstd chunk does not decompress");
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* context = nullptr;
    LZ4F_createDecompressionContext(&context, LZ4F_VERSION);
    size_t out_size = out.size(), in_size = data.size();
    const size_t status = LZ4F_decompress(context, out.data(), &out_size, data.data(), &in_size, nullptr);
    LZ4F_freeDecompressionContext(context);
    if (LZ4F_isError(status) || out_size != size) Corrupt(path, "an lz4 chunk does not decompress");
    return out;
  }
  Corrupt(path, "unknown chunk compression '" + std::string(compression) + "'");
}

class Scanner {
 public:
  Scanner(const std::string& path, const std::function<void(const McapMessage&)>& on_message)
      : path_(path), on_message_(on_message) {}

  // Records back to back; returns at the footer or where the bytes end.
  void Records(std::string_view bytes, bool top_level) {
    while (bytes.size() >= 9) {
      Cursor head{bytes, &path_};
      const uint8_t opcode = head.Int<uint8_t>();
      const uint64_t length = head.Int<uint64_t>();
      if (head.bytes.size() < length) {
        if (top_level) return;  // cut short by a killed writer
        Corrupt(path_, "a record inside a chunk runs past it");
      }
      Record(opcode, Cursor{head.bytes.substr(0, length), &path_});
      if (opcode == 0x02) return;  // footer
      bytes = head.bytes.substr(length);
    }
  }

 private:
  void Record(uint8_t opcode, Cursor body) {
    if (opcode == 0x03) {  // schema
      const uint16_t id = body.Int<uint16_t>();
      schemas_[id] = std::string(body.Str());
    } else if (opcode == 0x04) {  // channel
      const uint16_t id = body.Int<uint16_t>();
      const uint16_t schema = body.Int<uint16_t>();
      channels_[id] = {std::string(body.Str()), schema};
    } else if (opcode == 0x05) {  // message
      const uint16_t channel = body.Int<uint16_t>();
      body.Int<uint32_t>();  // sequence
      const uint64_t log_time = body.Int<uint64_t>();
      body.Int<uint64_t>();  // publish time
      const auto found = channels_.find(channel);
      if (found == channels_.end()) Corrupt(path_, "a message on channel " + std::to_string(channel) + " before its channel");
      on_message_({found->second.first, schemas_[found->second.second], log_time, body.bytes});
    } else if (opcode == 0x06) {  // chunk
      body.Int<uint64_t>();
      body.Int<uint64_t>();
      const uint64_t size = body.Int<uint64_t>();
      const uint32_t crc = body.Int<uint32_t>();
      const std::string_view compression = body.Str();
      const std::string records = Decompress(path_, compression, body.Take(body.Int<uint64_t>()), size);
      // 0 means "not computed" (the spec); our writer always computes it, other writers may not.
      if (crc != 0 && crc != static_cast<uint32_t>(::crc32(0, reinterpret_cast<const Bytef*>(records.data()),
                                                           static_cast<uInt>(records.size())))) {
        Corrupt(path_, "a chunk's CRC does not match its records");
      }
      Records(records, false);
    }
  }

  const std::string& path_;
  const std::function<void(const McapMessage&)>& on_message_;
  std::map<uint16_t, std::string> schemas_;
  std::map<uint16_t, std::pair<std::string, uint16_t>> channels_;
};

}  // namespace

void ReadMcap(const std::string& path, const std::string& label,
              const std::function<void(const McapMessage&)>& on_message) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(ErrorCode::kNotFound, "recording '" + label + "' cannot be opened: " + std::strerror(errno));
  std::string bytes(static_cast<size_t>(in.tellg()), '\0');  // read once, straight into place
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<size_t>(in.gcount()));
  static constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) Corrupt(label, "not an MCAP file");
  Scanner(label, on_message).Records(std::string_view(bytes).substr(8), true);
}

}  // namespace graspsim::recording
