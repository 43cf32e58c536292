// Little-endian integers in byte strings: the serialised forms meshseek
// stores (codebooks, neighbour graphs) are little-endian on every machine.
#ifndef MESHSEEK_COMMON_BASE_BYTE_ORDER_H_
#define MESHSEEK_COMMON_BASE_BYTE_ORDER_H_

#include <cstdint>
#include <cstring>
#include <string>

namespace meshseek {

/// Appends the low `bytes` bytes of `value`, least significant first.
inline void PutLittleEndian(uint64_t value, int bytes, std::string* out) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

/// Reads `bytes` bytes at `p`, least significant first.
inline uint64_t GetLittleEndian(const char* p, int bytes) {
  uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) {
    value |= static_cast<uint64_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  }
  return value;
}

/// A float's IEEE bits as four little-endian bytes, and back.
inline void PutFloat(float value, std::string* out) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  PutLittleEndian(bits, 4, out);
}
inline float GetFloat(const char* p) {
  const auto bits = static_cast<uint32_t>(GetLittleEndian(p, 4));
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_BYTE_ORDER_H_
