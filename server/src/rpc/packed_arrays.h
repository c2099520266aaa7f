// Big arrays on the wire (docs/architecture.md, Wire): a bytes field holds its values little-endian, back to
// back — float64 poses, paths and contacts, float32 vertices and points, uint32 indices, uint16 intensities.
// The one place rpc turns such a field into values and back. Unpacking checks that the field's length is a
// whole number of elements and names the field when it is not.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace graspsim::rpc {

// Values are copied as they are in memory, which is the wire's order only on a little-endian host.
static_assert(std::endian::native == std::endian::little, "graspsim's packed arrays assume a little-endian host");

// What one element of T is called in an error: "float64", "uint32", ...
template <typename T>
constexpr std::string_view PackedTypeName() {
  if constexpr (std::is_same_v<T, double>) return "float64";
  else if constexpr (std::is_same_v<T, float>) return "float32";
  else if constexpr (std::is_same_v<T, uint32_t>) return "uint32";
  else if constexpr (std::is_same_v<T, int32_t>) return "int32";
  else if constexpr (std::is_same_v<T, uint16_t>) return "uint16";
  else if constexpr (std::is_same_v<T, uint8_t>) return "uint8";
  else return "element";
}

// The number of `element_size`-byte elements in `bytes` bytes of field `field`. Throws Error(kInvalidArgument)
// "<field>: <n> bytes is not a multiple of <element_size> (<unit>)" otherwise.
size_t PackedCount(const std::string& field, size_t bytes, size_t element_size, std::string_view unit);

// `values` as a bytes field. T is a number or a fixed group of numbers without padding (std::array<uint32_t, 3>,
// Eigen::Vector3f).
template <typename T>
std::string Pack(const std::vector<T>& values) {
  static_assert(std::is_standard_layout_v<T>);
  std::string bytes(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());  // no memcpy from an empty vector's nullptr
  return bytes;
}

// Rows (Eigen vectors, e.g. a path's waypoints) one after the other.
template <typename Row>
std::string PackRows(const std::vector<Row>& rows) {
  using Scalar = typename Row::Scalar;
  size_t count = 0;
  for (const Row& row : rows) count += static_cast<size_t>(row.size());
  std::string bytes(count * sizeof(Scalar), '\0');
  size_t at = 0;
  for (const Row& row : rows) {
    const size_t size = static_cast<size_t>(row.size()) * sizeof(Scalar);
    if (size > 0) std::memcpy(bytes.data() + at, row.data(), size);
    at += size;
  }
  return bytes;
}

// Bytes field `field` as values of T; `unit` says what one element is in the error ("three float32 per vertex").
template <typename T>
std::vector<T> Unpack(const std::string& field, std::string_view bytes, std::string_view unit = PackedTypeName<T>()) {
  static_assert(std::is_standard_layout_v<T>);
  std::vector<T> values(PackedCount(field, bytes.size(), sizeof(T), unit));
  // No memcpy to an empty vector's nullptr; the cast: Eigen vectors are plain floats whatever their copy-assignment says.
  if (!values.empty()) std::memcpy(static_cast<void*>(values.data()), bytes.data(), bytes.size());
  return values;
}

// Points (Vec3, or per-texel forces) as float32 x y z, 12 bytes each, and back. Templates, so that this header
// needs no Eigen (http_viewer.cpp includes it after httplib, whose <resolv.h> defines a macro Eigen's headers use).
template <typename Point>
std::string PackFloat32Xyz(const std::vector<Point>& points) {
  std::vector<float> raw;
  raw.reserve(3 * points.size());
  for (const Point& p : points) raw.insert(raw.end(), {float(p.x()), float(p.y()), float(p.z())});
  return Pack(raw);
}
template <typename Point>
std::vector<Point> UnpackFloat32Xyz(const std::string& field, std::string_view bytes) {
  const std::vector<std::array<float, 3>> raw = Unpack<std::array<float, 3>>(field, bytes, "float32 x y z per point");
  std::vector<Point> points;
  points.reserve(raw.size());
  for (const auto& p : raw) points.emplace_back(p[0], p[1], p[2]);
  return points;
}

}  // namespace graspsim::rpc
