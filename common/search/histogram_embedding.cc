#include "common/search/histogram_embedding.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

// Extra sketch columns beyond the dimensions kept, and power iterations
// (Halko et al. recommend 5..10 and 1..2 for slowly decaying spectra; on PSB
// train two iterations instead of one changed recall@10 by under 0.001).
constexpr int kOversampling = 10;
constexpr int kPowerIterations = 1;

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Standard normal number `i` of the stream `seed` (Box-Muller on two
// counter-based uniforms): the same on every machine and library.
double Gaussian(uint64_t seed, uint64_t i) {
  const double u1 = (static_cast<double>(SplitMix64(seed + 2 * i) >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = static_cast<double>(SplitMix64(seed + 2 * i + 1) >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

// A dense matrix, row-major.
struct Matrix {
  std::size_t rows = 0, cols = 0;
  std::vector<double> v;
  Matrix(std::size_t r, std::size_t c) : rows(r), cols(c), v(r * c, 0.0) {}
  double* row(std::size_t i) { return &v[i * cols]; }
  const double* row(std::size_t i) const { return &v[i * cols]; }
};

// The sample as sparse rows of square roots, and their mean.
struct SqrtRows {
  std::vector<std::size_t> start{0};
  std::vector<uint32_t> words;
  std::vector<double> roots;
  std::vector<double> mean;  // per word
  std::size_t size() const { return start.size() - 1; }
};

// Y = (S - 1 mean^T) M for M (V x l): m x l.
Matrix TimesRight(const SqrtRows& s, const Matrix& m) {
  Matrix y(s.size(), m.cols);
  std::vector<double> mean_m(m.cols, 0.0);
  for (std::size_t k = 0; k < m.rows; ++k) {
    for (std::size_t j = 0; j < m.cols; ++j) mean_m[j] += s.mean[k] * m.row(k)[j];
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    double* out = y.row(i);
    for (std::size_t t = s.start[i]; t < s.start[i + 1]; ++t) {
      const double r = s.roots[t];
      const double* in = m.row(s.words[t]);
      for (std::size_t j = 0; j < m.cols; ++j) out[j] += r * in[j];
    }
    for (std::size_t j = 0; j < m.cols; ++j) out[j] -= mean_m[j];
  }
  return y;
}

// Z = (S - 1 mean^T)^T N for N (m x l): V x l.
Matrix TimesLeft(const SqrtRows& s, const Matrix& n, std::size_t vocabulary) {
  Matrix z(vocabulary, n.cols);
  std::vector<double> column_sums(n.cols, 0.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double* in = n.row(i);
    for (std::size_t j = 0; j < n.cols; ++j) column_sums[j] += in[j];
    for (std::size_t t = s.start[i]; t < s.start[i + 1]; ++t) {
      const double r = s.roots[t];
      double* out = z.row(s.words[t]);
      for (std::size_t j = 0; j < n.cols; ++j) out[j] += r * in[j];
    }
  }
  for (std::size_t k = 0; k < vocabulary; ++k) {
    for (std::size_t j = 0; j < n.cols; ++j) z.row(k)[j] -= s.mean[k] * column_sums[j];
  }
  return z;
}

// Orthonormalises the columns of `a` in place: modified Gram-Schmidt, twice
// ("twice is enough", Giraud et al. 2005), on a column-major copy so that
// every dot product and update runs over contiguous memory. A column that is
// (numerically) in the span of the previous ones becomes zero.
void Orthonormalise(Matrix* a) {
  const std::size_t rows = a->rows, cols = a->cols;
  std::vector<double> c(rows * cols);  // column j at c[j * rows]
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < cols; ++j) c[j * rows + i] = a->row(i)[j];
  }
  auto dot = [rows](const double* x, const double* y) {
    double sum = 0.0;
    for (std::size_t i = 0; i < rows; ++i) sum += x[i] * y[i];
    return sum;
  };
  // Columns by pointer arithmetic on data(): with no rows (a sample without
  // features) c is empty, and &c[0] would bind a reference to null (UBSan).
  auto column = [&c, rows](std::size_t j) { return c.data() + j * rows; };
  std::vector<double> original(cols);
  for (std::size_t j = 0; j < cols; ++j) original[j] = dot(column(j), column(j));
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t j = 0; j < cols; ++j) {
      double* cj = column(j);
      for (std::size_t p = 0; p < j; ++p) {
        const double* cp = column(p);
        const double r = dot(cp, cj);
        for (std::size_t i = 0; i < rows; ++i) cj[i] -= r * cp[i];
      }
      const double norm = dot(cj, cj);
      const bool dependent = !(norm > 1e-20 * std::max(original[j], 1e-300));
      const double scale = dependent ? 0.0 : 1.0 / std::sqrt(norm);
      for (std::size_t i = 0; i < rows; ++i) cj[i] *= scale;
    }
  }
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < cols; ++j) a->row(i)[j] = c[j * rows + i];
  }
}

// Eigen-decomposition of the symmetric n x n matrix `g` by cyclic Jacobi
// rotations: eigenvalues into `values`, eigenvectors as the columns of
// `vectors`.
void SymmetricEigen(Matrix g, std::vector<double>* values, Matrix* vectors) {
  const std::size_t n = g.rows;
  *vectors = Matrix(n, n);
  for (std::size_t i = 0; i < n; ++i) vectors->row(i)[i] = 1.0;
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0.0, total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        total += g.row(i)[j] * g.row(i)[j];
        if (i != j) off += g.row(i)[j] * g.row(i)[j];
      }
    }
    if (!(off > 1e-30 * total)) break;
    for (std::size_t p = 0; p + 1 < n; ++p) {
      for (std::size_t q = p + 1; q < n; ++q) {
        const double apq = g.row(p)[q];
        if (apq == 0.0) continue;
        const double theta = (g.row(q)[q] - g.row(p)[p]) / (2.0 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1.0 / std::sqrt(t * t + 1), s = t * c;
        for (std::size_t k = 0; k < n; ++k) {  // columns p, q
          const double gkp = g.row(k)[p], gkq = g.row(k)[q];
          g.row(k)[p] = c * gkp - s * gkq;
          g.row(k)[q] = s * gkp + c * gkq;
        }
        for (std::size_t k = 0; k < n; ++k) {  // rows p, q
          const double gpk = g.row(p)[k], gqk = g.row(q)[k];
          g.row(p)[k] = c * gpk - s * gqk;
          g.row(q)[k] = s * gpk + c * gqk;
        }
        for (std::size_t k = 0; k < n; ++k) {
          const double vkp = vectors->row(k)[p], vkq = vectors->row(k)[q];
          vectors->row(k)[p] = c * vkp - s * vkq;
          vectors->row(k)[q] = s * vkp + c * vkq;
        }
      }
    }
  }
  values->resize(n);
  for (std::size_t i = 0; i < n; ++i) (*values)[i] = g.row(i)[i];
}

}  // namespace

absl::StatusOr<HistogramEmbedding> HistogramEmbedding::Fit(absl::Span<const SparseHistogram> sample,
                                                           uint32_t vocabulary,
                                                           int dimensions,
                                                           uint64_t seed) {
  if (dimensions < 1 || dimensions > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("embedding: dimensions must be in [1, 1024], got ", dimensions));
  }
  if (vocabulary == 0) return absl::InvalidArgumentError("embedding: vocabulary 0");
  SqrtRows s;
  s.mean.assign(vocabulary, 0.0);
  for (std::size_t h = 0; h < sample.size(); ++h) {
    const SparseHistogram& x = sample[h];
    if (x.vocabulary != vocabulary) {
      return absl::InvalidArgumentError(absl::StrCat("embedding: sample histogram ", h, " has ",
                                                     x.vocabulary, " words, expected ",
                                                     vocabulary));
    }
    if (x.empty()) continue;
    for (std::size_t t = 0; t < x.words.size(); ++t) {
      s.words.push_back(x.words[t]);
      s.roots.push_back(std::sqrt(static_cast<double>(x.weights[t])));
      s.mean[x.words[t]] += s.roots.back();
    }
    s.start.push_back(s.words.size());
  }
  const std::size_t m = s.size();
  for (double& v : s.mean) v = m == 0 ? 0.0 : v / static_cast<double>(m);

  const std::size_t l = static_cast<std::size_t>(dimensions + kOversampling);
  Matrix omega(vocabulary, l);
  for (std::size_t i = 0; i < omega.v.size(); ++i) omega.v[i] = Gaussian(seed, i);
  Matrix y = TimesRight(s, omega);
  Orthonormalise(&y);
  for (int it = 0; it < kPowerIterations; ++it) {
    Matrix z = TimesLeft(s, y, vocabulary);
    Orthonormalise(&z);
    y = TimesRight(s, z);
    Orthonormalise(&y);
  }
  // B = Y^T A has the principal right singular vectors of A (within the
  // sketch): with Z = B^T, those of B are Z w / sqrt(lambda) for the
  // eigenpairs (lambda, w) of Z^T Z.
  const Matrix z = TimesLeft(s, y, vocabulary);
  Matrix gram(l, l);
  for (std::size_t k = 0; k < vocabulary; ++k) {
    const double* zk = z.row(k);
    for (std::size_t i = 0; i < l; ++i) {
      for (std::size_t j = 0; j < l; ++j) gram.row(i)[j] += zk[i] * zk[j];
    }
  }
  std::vector<double> lambda;
  Matrix w(0, 0);
  SymmetricEigen(std::move(gram), &lambda, &w);
  std::vector<std::size_t> order(l);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return lambda[a] > lambda[b]; });
  const double top = l == 0 ? 0.0 : std::max(lambda[order[0]], 0.0);
  const std::size_t d = static_cast<std::size_t>(dimensions);
  std::vector<float> axes(static_cast<std::size_t>(vocabulary) * d, 0.0f);
  for (std::size_t a = 0; a < d; ++a) {
    const std::size_t e = order[a];
    if (!(lambda[e] > 1e-12 * top) || !(top > 0)) continue;  // no such axis in the sample
    const double inv = 1.0 / std::sqrt(lambda[e]);
    for (std::size_t k = 0; k < vocabulary; ++k) {
      double v = 0.0;
      for (std::size_t j = 0; j < l; ++j) v += z.row(k)[j] * w.row(j)[e];
      axes[k * d + a] = static_cast<float>(v * inv);
    }
  }
  return HistogramEmbedding(vocabulary, dimensions, std::move(axes));
}

void HistogramEmbedding::Embed(absl::Span<const uint32_t> words,
                               absl::Span<const float> weights,
                               float* out) const {
  const std::size_t d = static_cast<std::size_t>(dimensions_);
  std::fill(out, out + d, 0.0f);
  for (std::size_t t = 0; t < words.size(); ++t) {
    const float root = std::sqrt(weights[t]);
    const float* axis = &axes_[static_cast<std::size_t>(words[t]) * d];
    for (std::size_t j = 0; j < d; ++j) out[j] += root * axis[j];
  }
}

}  // namespace meshseek
