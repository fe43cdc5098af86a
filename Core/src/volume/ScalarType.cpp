// Sizes and names of the in-memory scalar types.
#include "repose/volume/ScalarType.h"

namespace repose {

std::size_t scalarSize(ScalarType t) {
  switch (t) {
    case ScalarType::UInt8:
      return 1;
    case ScalarType::UInt16:
    case ScalarType::Int16:
      return 2;
    case ScalarType::Int32:
    case ScalarType::Float32:
      return 4;
  }
  return 1;
}

const char* scalarTypeName(ScalarType t) {
  switch (t) {
    case ScalarType::UInt8:
      return "uint8";
    case ScalarType::UInt16:
      return "uint16";
    case ScalarType::Int16:
      return "int16";
    case ScalarType::Int32:
      return "int32";
    case ScalarType::Float32:
      return "float32";
  }
  return "?";
}

bool isIntegerType(ScalarType t) {
  return t != ScalarType::Float32;
}

}  // namespace repose
