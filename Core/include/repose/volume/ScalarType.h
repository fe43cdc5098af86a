// The voxel scalar types Repose keeps in memory; every reader converts to one of these.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace repose {

enum class ScalarType { UInt8, UInt16, Int16, Int32, Float32 };

std::size_t scalarSize(ScalarType t);
// Lower-case names as printed by `repose info`: uint8, uint16, int16, int32, float32.
const char* scalarTypeName(ScalarType t);
bool isIntegerType(ScalarType t);

template <class T>
constexpr ScalarType scalarTypeOf();
template <>
constexpr ScalarType scalarTypeOf<std::uint8_t>() {
  return ScalarType::UInt8;
}
template <>
constexpr ScalarType scalarTypeOf<std::uint16_t>() {
  return ScalarType::UInt16;
}
template <>
constexpr ScalarType scalarTypeOf<std::int16_t>() {
  return ScalarType::Int16;
}
template <>
constexpr ScalarType scalarTypeOf<std::int32_t>() {
  return ScalarType::Int32;
}
template <>
constexpr ScalarType scalarTypeOf<float>() {
  return ScalarType::Float32;
}

// Calls f with a null pointer of the C++ type matching t, so generic code can switch on type once:
//   dispatchScalar(t, [&](auto* tag) { using T = std::remove_pointer_t<decltype(tag)>; ... });
template <class F>
decltype(auto) dispatchScalar(ScalarType t, F&& f) {
  switch (t) {
    case ScalarType::UInt8:
      return f(static_cast<std::uint8_t*>(nullptr));
    case ScalarType::UInt16:
      return f(static_cast<std::uint16_t*>(nullptr));
    case ScalarType::Int16:
      return f(static_cast<std::int16_t*>(nullptr));
    case ScalarType::Int32:
      return f(static_cast<std::int32_t*>(nullptr));
    case ScalarType::Float32:
      break;
  }
  return f(static_cast<float*>(nullptr));
}

}  // namespace repose
