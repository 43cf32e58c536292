#include "common/geometry/sobol.h"

namespace meshseek {
namespace {

struct Dimension {
  int degree;           // degree of the primitive polynomial
  uint32_t inner;       // its interior coefficients as bits (NR's "ip")
  uint32_t initial[2];  // initial direction numbers m_1 .. m_degree
};
// x + 1 and x^2 + x + 1, with NR's initial values.
constexpr Dimension kDimensions[2] = {{1, 0, {1, 0}}, {2, 1, {1, 1}}};

}  // namespace

Sobol2D::Sobol2D() {
  for (int j = 0; j < 2; ++j) {
    const Dimension& dim = kDimensions[j];
    auto& v = direction_[j];
    for (int k = 0; k < dim.degree; ++k) v[k] = dim.initial[k] << (kBits - 1 - k);
    // Recurrence of NR's sobseq: v_k = v_{k-d} ^ (v_{k-d} >> d) ^ sum of a_l v_{k-l}.
    for (int k = dim.degree; k < kBits; ++k) {
      uint32_t value = v[k - dim.degree];
      value ^= value >> dim.degree;
      uint32_t coeffs = dim.inner;
      for (int l = dim.degree - 1; l >= 1; --l) {
        if (coeffs & 1u) value ^= v[k - l];
        coeffs >>= 1;
      }
      v[k] = value;
    }
  }
}

std::array<double, 2> Sobol2D::Next() {
  // Gray-code order: flip the direction number of the lowest zero bit of the index.
  int bit = 0;
  for (uint32_t i = index_; (i & 1u) != 0; i >>= 1) ++bit;
  if (bit >= kBits) {  // period exhausted: restart
    index_ = 0;
    state_ = {0, 0};
    bit = 0;
  }
  constexpr double kScale = 1.0 / static_cast<double>(1u << kBits);
  std::array<double, 2> point;
  for (int j = 0; j < 2; ++j) {
    state_[j] ^= direction_[j][bit];
    point[j] = state_[j] * kScale;
  }
  ++index_;
  return point;
}

}  // namespace meshseek
