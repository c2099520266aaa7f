#include "persistence/scene_archive.h"

#include <cstring>
#include <memory>

#include "core/error.h"
#include "core/sha256.h"
#include "persistence/state_codec.h"

namespace graspsim::persistence {
namespace {

// "graspsim scene archive", version 1. Fields are little-endian u64 counts and length-prefixed strings.
constexpr std::string_view kMagic = "GSSCENE\x01";

void PutU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void PutBytes(std::string* out, std::string_view bytes) {
  PutU64(out, bytes.size());
  out->append(bytes);
}

class Reader {
 public:
  Reader(std::string_view bytes, const std::string& field) : bytes_(bytes), field_(field) {}

  uint64_t U64() {
    Need(8, "a number");
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(static_cast<unsigned char>(bytes_[at_ + i])) << (8 * i);
    at_ += 8;
    return v;
  }

  std::string Bytes(const char* what) {
    const uint64_t size = U64();
    Need(size, what);
    std::string out(bytes_.substr(at_, size));
    at_ += size;
    return out;
  }

  [[noreturn]] void Fail(const std::string& why) const {
    ThrowInvalidArgument(field_ + ": not a graspsim scene archive (" + why + " at byte " + std::to_string(at_) + ")");
  }

  size_t remaining() const { return bytes_.size() - at_; }

 private:
  void Need(uint64_t size, const char* what) const {
    if (size > remaining()) Fail(std::string("truncated: ") + what + " of " + std::to_string(size) + " bytes");
  }

  std::string_view bytes_;
  const std::string& field_;
  size_t at_ = 0;
};

}  // namespace

std::string EncodeSceneArchive(const SceneArchive& archive) {
  std::string out(kMagic);
  PutBytes(&out, archive.id);
  PutBytes(&out, archive.name);
  PutU64(&out, archive.revision);
  PutU64(&out, archive.ops.size());
  for (const SceneOp& op : archive.ops) {
    PutBytes(&out, op.kind);
    PutBytes(&out, op.payload);
    PutBytes(&out, op.path);
    PutBytes(&out, op.sha256);
    PutBytes(&out, op.file ? std::string_view(*op.file) : std::string_view());
  }
  PutBytes(&out, EncodeState(archive.state));
  return out;
}

SceneArchive DecodeSceneArchive(std::string_view bytes, const std::string& field) {
  Reader in(bytes.substr(std::min(bytes.size(), kMagic.size())), field);
  if (!bytes.starts_with(kMagic)) in.Fail("no GSSCENE version 1 header");
  SceneArchive archive;
  archive.id = in.Bytes("the id");
  archive.name = in.Bytes("the name");
  archive.revision = in.U64();
  const uint64_t count = in.U64();
  if (count > in.remaining() / 40) in.Fail(std::to_string(count) + " edits cannot fit");  // 5 sizes each at least
  for (uint64_t i = 0; i < count; ++i) {
    SceneOp op;
    op.kind = in.Bytes("an edit's kind");
    op.payload = in.Bytes("an edit's request");
    op.path = in.Bytes("a file's path");
    op.sha256 = in.Bytes("a file's SHA-256");
    std::string file = in.Bytes("a file");
    if (op.kind == "UploadFile") {
      if (Sha256Hex(file) != op.sha256) in.Fail("file " + op.path + " does not match its SHA-256");
      op.file = std::make_shared<const std::string>(std::move(file));
    }
    archive.ops.push_back(std::move(op));
  }
  const std::string state = in.Bytes("the state");
  if (in.remaining() != 0) in.Fail(std::to_string(in.remaining()) + " bytes after the end");
  try {
    archive.state = DecodeState(state, field + " state");
  } catch (const Error& error) {
    in.Fail(error.what());
  }
  return archive;
}

}  // namespace graspsim::persistence
