// Two-dimensional Sobol quasi-random sequence, as in Numerical Recipes in C
// (2nd ed., sec. 7.7, "sobseq"), the generator the seed paper cites (ref. [8]).
//
// Dimension 1 uses the primitive polynomial x + 1 with initial direction number
// m1 = 1; dimension 2 uses x^2 + x + 1 with m = (1, 1); 30 bits, Gray-code
// order. The first points are (0.5, 0.5), (0.25, 0.75), (0.75, 0.25),
// (0.375, 0.625), ... (docs/design.md 2.1). Low discrepancy gives lower variance in
// sample density than pseudo-random numbers, and the sequence is fully
// deterministic, so resampling a model always gives the same points.
#ifndef MESHSEEK_COMMON_GEOMETRY_SOBOL_H_
#define MESHSEEK_COMMON_GEOMETRY_SOBOL_H_

#include <array>
#include <cstdint>

namespace meshseek {

class Sobol2D {
 public:
  static constexpr int kBits = 30;

  Sobol2D();

  // Next point of the sequence, both coordinates in (0, 1). The sequence has
  // period 2^30; it restarts from the beginning after that.
  std::array<double, 2> Next();

 private:
  std::array<std::array<uint32_t, kBits>, 2> direction_;  // v_k, scaled to 30 bits
  std::array<uint32_t, 2> state_{0, 0};
  uint32_t index_ = 0;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_SOBOL_H_
