// Little-endian packing of plain values into a byte string and back, for the blobs the SQLite stores keep
// (grasp sets, scene states). x86 and ARM are little-endian and the formats are ours alone, so values are
// copied as they are in memory. A reader that runs out of bytes throws instead of reading past the end.
#pragma once

#include <cstring>
#include <string>
#include <type_traits>

#include "core/error.h"
#include "core/math.h"

namespace graspsim {

class ByteWriter {
 public:
  template <typename T>
  void Put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  void Put(const Vec3& v) {
    for (int k = 0; k < 3; ++k) Put(v[k]);
  }
  const std::string& bytes() const { return bytes_; }
  std::string Take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // `what` names the blob in the error a short read throws (kInternal: stored data that is not what we wrote).
  ByteReader(const void* data, size_t size, std::string what)
      : data_(static_cast<const char*>(data)), size_(size), what_(std::move(what)) {}
  template <typename T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value{};
    if (at_ + sizeof(T) > size_) throw Error(ErrorCode::kInternal, what_ + ": truncated");
    std::memcpy(&value, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  Vec3 GetVec3() {
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = Get<double>();
    return v;
  }
  // A count of elements that each take at least `element_bytes`: checked against what is left, so a corrupt
  // count cannot ask for a huge allocation.
  size_t GetCount(size_t element_bytes) {
    const uint64_t n = Get<uint64_t>();
    if (element_bytes > 0 && n > (size_ - at_) / element_bytes) {
      throw Error(ErrorCode::kInternal, what_ + ": a count of " + std::to_string(n) + " exceeds the data");
    }
    return static_cast<size_t>(n);
  }
  bool done() const { return at_ == size_; }

 private:
  const char* data_;
  size_t size_, at_ = 0;
  std::string what_;
};

}  // namespace graspsim
