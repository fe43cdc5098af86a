#include "CompactGreenMatrix.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <zlib.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <istream>
#include <ostream>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#include <immintrin.h>
#define REPOSE_HAVE_X86 1
#endif

namespace repose {
namespace {

constexpr Eigen::Index kLanes = 16;   // halves per step of the vector kernels (two 8-float loads)
constexpr double kHalfLimit = 32768;  // keep |stored coefficient| well below half's 65504
// The low half stores (c - high) * 2^11: the residual is below 2^-11 |c|, so scaled it has c's
// magnitude and keeps 11 significant bits instead of sinking into half's subnormals.
constexpr float kLowScale = 2048.0f, kLowUnscale = 1.0f / 2048.0f;

std::uint16_t toHalf(float v) {
  return Eigen::numext::bit_cast<std::uint16_t>(Eigen::half(v));
}
float fromHalf(std::uint16_t h) {
  return static_cast<float>(Eigen::numext::bit_cast<Eigen::half>(h));
}

// Portable kernel for CPUs without F16C: the same arithmetic, one coefficient at a time.
// Kernels compute output rows [begin, end): of the whole matrix, or of the matrix rows listed in
// `rows` when it is not null.
void multiplyRowsScalar(const std::uint16_t* high, const std::uint16_t* low, Eigen::Index stride,
                        Eigen::Index cols, const double* x0, const double* x1, const double* x2,
                        const std::int64_t* rows, std::int64_t begin, std::int64_t end,
                        double* out) {
  for (std::int64_t o = begin; o < end; ++o) {
    const std::int64_t r = rows ? rows[o] : o;
    const std::uint16_t* h = high + r * stride;
    const std::uint16_t* l = low ? low + r * stride : nullptr;
    double y0 = 0, y1 = 0, y2 = 0;
    for (Eigen::Index j = 0; j < cols; ++j) {
      const double c =
          l ? double(fromHalf(h[j]) + kLowUnscale * fromHalf(l[j])) : double(fromHalf(h[j]));
      y0 += c * x0[j], y1 += c * x1[j], y2 += c * x2[j];
    }
    out[3 * o] = y0, out[3 * o + 1] = y1, out[3 * o + 2] = y2;
  }
}

#ifdef REPOSE_HAVE_X86
bool cpuHasF16c() {
  // F16C from CPUID itself: clang's __builtin_cpu_supports does not know "f16c".
  static const bool has = [] {
    unsigned a = 0, b = 0, c = 0, d = 0;
    const bool f16c = __get_cpuid(1, &a, &b, &c, &d) && (c & bit_F16C);
    return f16c && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
}

__attribute__((target("avx2,fma,f16c"))) double horizontalSum(__m256 v) {
  alignas(32) float lanes[8];
  _mm256_store_ps(lanes, v);
  double s = 0;
  for (float f : lanes) s += f;
  return s;
}
__attribute__((target("avx2,fma,f16c"))) double horizontalSum(__m256d v) {
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, v);
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// Preview: high halves only, float lanes (the displacements are small, so float sums suffice).
__attribute__((target("avx2,fma,f16c"))) void multiplyRowsPreview(
    const std::uint16_t* high, Eigen::Index stride, const float* x0, const float* x1,
    const float* x2, const std::int64_t* rows, std::int64_t begin, std::int64_t end, double* out) {
  for (std::int64_t o = begin; o < end; ++o) {
    const std::int64_t r = rows ? rows[o] : o;
    const std::uint16_t* h = high + r * stride;
    __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, b0 = a0, b1 = a0, b2 = a0;
    for (Eigen::Index i = 0; i < stride; i += kLanes) {
      const __m256 c = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h + i)));
      const __m256 d =
          _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h + i + 8)));
      a0 = _mm256_fmadd_ps(c, _mm256_loadu_ps(x0 + i), a0);
      a1 = _mm256_fmadd_ps(c, _mm256_loadu_ps(x1 + i), a1);
      a2 = _mm256_fmadd_ps(c, _mm256_loadu_ps(x2 + i), a2);
      b0 = _mm256_fmadd_ps(d, _mm256_loadu_ps(x0 + i + 8), b0);
      b1 = _mm256_fmadd_ps(d, _mm256_loadu_ps(x1 + i + 8), b1);
      b2 = _mm256_fmadd_ps(d, _mm256_loadu_ps(x2 + i + 8), b2);
    }
    out[3 * o] = horizontalSum(_mm256_add_ps(a0, b0));
    out[3 * o + 1] = horizontalSum(_mm256_add_ps(a1, b1));
    out[3 * o + 2] = horizontalSum(_mm256_add_ps(a2, b2));
  }
}

// Exact: c = high + low / 2^11 in float, accumulated in double lanes.
__attribute__((target("avx2,fma,f16c"))) void multiplyRowsExact(
    const std::uint16_t* high, const std::uint16_t* low, Eigen::Index stride, const double* x0,
    const double* x1, const double* x2, const std::int64_t* rows, std::int64_t begin,
    std::int64_t end, double* out) {
  for (std::int64_t o = begin; o < end; ++o) {
    const std::int64_t r = rows ? rows[o] : o;
    const std::uint16_t* h = high + r * stride;
    const std::uint16_t* l = low + r * stride;
    const __m256 unscale = _mm256_set1_ps(kLowUnscale);
    __m256d a0 = _mm256_setzero_pd(), a1 = a0, a2 = a0;
    for (Eigen::Index i = 0; i < stride; i += 8) {
      const __m256 c = _mm256_fmadd_ps(
          _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(l + i))), unscale,
          _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h + i))));
      const __m256d lo = _mm256_cvtps_pd(_mm256_castps256_ps128(c));
      const __m256d hi = _mm256_cvtps_pd(_mm256_extractf128_ps(c, 1));
      a0 = _mm256_fmadd_pd(lo, _mm256_loadu_pd(x0 + i), a0);
      a0 = _mm256_fmadd_pd(hi, _mm256_loadu_pd(x0 + i + 4), a0);
      a1 = _mm256_fmadd_pd(lo, _mm256_loadu_pd(x1 + i), a1);
      a1 = _mm256_fmadd_pd(hi, _mm256_loadu_pd(x1 + i + 4), a1);
      a2 = _mm256_fmadd_pd(lo, _mm256_loadu_pd(x2 + i), a2);
      a2 = _mm256_fmadd_pd(hi, _mm256_loadu_pd(x2 + i + 4), a2);
    }
    out[3 * o] = horizontalSum(a0), out[3 * o + 1] = horizontalSum(a1);
    out[3 * o + 2] = horizontalSum(a2);
  }
}
#endif

}  // namespace

CompactGreenMatrix::CompactGreenMatrix(const Eigen::MatrixXd& phi, const Eigen::MatrixXd& psi)
    : CompactGreenMatrix(phi.rows(), phi.cols(), psi.cols()) {
  setRows(0, phi, psi);
}

CompactGreenMatrix::CompactGreenMatrix(Eigen::Index rows, Eigen::Index vertexCols,
                                       Eigen::Index faceCols)
    : rows_(rows), cols_(vertexCols + faceCols), vertexCols_(vertexCols) {
  stride_ = (cols_ + kLanes - 1) / kLanes * kLanes;
  high_.assign(static_cast<std::size_t>(rows_ * stride_), 0);
  low_.assign(high_.size(), 0);
  rowScale_ = Eigen::VectorXd::Ones(rows_);
}

void CompactGreenMatrix::setRows(Eigen::Index first, const Eigen::MatrixXd& phi,
                                 const Eigen::MatrixXd& psi) {
  if (psi.rows() != phi.rows() || phi.cols() != vertexCols_ || phi.cols() + psi.cols() != cols_ ||
      first < 0 || first + phi.rows() > rows_)
    throw Error("Green coordinates: a block that does not fit the matrix");
  const Eigen::Index nv = vertexCols_;
  parallelFor(phi.rows(), 0, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t b = begin; b < end; ++b) {
      const std::int64_t r = first + b;
      double largest = 0;
      for (Eigen::Index j = 0; j < cols_; ++j)
        largest = std::max(largest, std::fabs(j < nv ? phi(b, j) : psi(b, j - nv)));
      if (!std::isfinite(largest)) throw Error("Green coordinates are not finite");
      const double scale = largest > kHalfLimit ? kHalfLimit / largest : 1.0;
      rowScale_[r] = scale;
      for (Eigen::Index j = 0; j < cols_; ++j) {
        const double c = scale * (j < nv ? phi(b, j) : psi(b, j - nv));
        const std::uint16_t h = toHalf(static_cast<float>(c));
        const std::size_t at = static_cast<std::size_t>(r * stride_ + j);
        high_[at] = h;
        low_[at] = toHalf(static_cast<float>(kLowScale * (c - double(fromHalf(h)))));
      }
    }
  });
}

Eigen::MatrixX3d CompactGreenMatrix::multiply(const Eigen::MatrixX3d& x, bool preview,
                                              int threads) const {
  return multiplyRows(x, preview, threads, nullptr);
}

Eigen::MatrixX3d CompactGreenMatrix::multiplyRows(const Eigen::MatrixX3d& x, bool preview,
                                                  int threads,
                                                  const std::vector<std::int64_t>* rows) const {
  if (x.rows() != cols_) throw Error("Green coordinates: wrong number of cage values");
  if (rows)
    for (const std::int64_t r : *rows)
      if (r < 0 || r >= rows_) throw Error("Green coordinates: a row out of range");
  // Columns of x, padded with zeros to the stride (the padding coefficients are zero too).
  std::vector<double> xd(static_cast<std::size_t>(3 * stride_), 0.0);
  std::vector<float> xf(xd.size(), 0.0f);
  for (int k = 0; k < 3; ++k)
    for (Eigen::Index j = 0; j < cols_; ++j) {
      xd[k * stride_ + j] = x(j, k);
      xf[k * stride_ + j] = static_cast<float>(x(j, k));
    }
  const std::int64_t n = rows ? std::int64_t(rows->size()) : rows_;
  const std::int64_t* list = rows ? rows->data() : nullptr;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> out(n, 3);
  const double* d = xd.data();
  const float* f = xf.data();
  parallelFor(n, threads, [&](std::int64_t begin, std::int64_t end) {
#ifdef REPOSE_HAVE_X86
    if (cpuHasF16c()) {
      if (preview)
        multiplyRowsPreview(high_.data(), stride_, f, f + stride_, f + 2 * stride_, list, begin,
                            end, out.data());
      else
        multiplyRowsExact(high_.data(), low_.data(), stride_, d, d + stride_, d + 2 * stride_, list,
                          begin, end, out.data());
      return;
    }
#endif
    multiplyRowsScalar(high_.data(), preview ? nullptr : low_.data(), stride_, cols_, d,
                       d + stride_, d + 2 * stride_, list, begin, end, out.data());
  });
  Eigen::VectorXd inverseScale(n);
  for (std::int64_t o = 0; o < n; ++o) inverseScale[o] = 1.0 / rowScale_[list ? list[o] : o];
  return inverseScale.asDiagonal() * out;
}

}  // namespace repose

namespace repose {

void CompactGreenMatrix::writeTo(std::ostream& out) const {
  const std::int64_t sizes[4] = {rows_, cols_, vertexCols_, stride_};
  out.write(reinterpret_cast<const char*>(sizes), sizeof(sizes));
  out.write(reinterpret_cast<const char*>(rowScale_.data()),
            static_cast<std::streamsize>(rowScale_.size() * sizeof(double)));
  for (const auto* halves : {&high_, &low_})
    out.write(reinterpret_cast<const char*>(halves->data()),
              static_cast<std::streamsize>(halves->size() * sizeof(std::uint16_t)));
}

bool CompactGreenMatrix::readFrom(std::istream& in, Eigen::Index rows, Eigen::Index vertexCols,
                                  Eigen::Index faceCols) {
  CompactGreenMatrix m(rows, vertexCols, faceCols);
  std::int64_t sizes[4] = {};
  if (!in.read(reinterpret_cast<char*>(sizes), sizeof(sizes))) return false;
  if (sizes[0] != m.rows_ || sizes[1] != m.cols_ || sizes[2] != m.vertexCols_ ||
      sizes[3] != m.stride_)
    return false;
  in.read(reinterpret_cast<char*>(m.rowScale_.data()),
          static_cast<std::streamsize>(m.rowScale_.size() * sizeof(double)));
  for (auto* halves : {&m.high_, &m.low_})
    in.read(reinterpret_cast<char*>(halves->data()),
            static_cast<std::streamsize>(halves->size() * sizeof(std::uint16_t)));
  if (!in) return false;
  if (!m.rowScale_.allFinite() || (m.rowScale_.array() <= 0).any()) return false;
  *this = std::move(m);
  return true;
}

std::uint32_t CompactGreenMatrix::checksum(int threads) const {
  // Pieces of 8 MiB checked in parallel and combined in order (crc32_combine), so the CRC is that
  // of the arrays end to end whatever the thread count.
  std::vector<std::pair<const unsigned char*, std::size_t>> spans;
  constexpr std::size_t kPiece = std::size_t(8) << 20;
  const auto add = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t at = 0; at < bytes; at += kPiece)
      spans.emplace_back(p + at, std::min(kPiece, bytes - at));
  };
  add(rowScale_.data(), rowScale_.size() * sizeof(double));
  add(high_.data(), high_.size() * sizeof(std::uint16_t));
  add(low_.data(), low_.size() * sizeof(std::uint16_t));
  std::vector<uLong> crcs(spans.size());
  parallelFor(
      static_cast<std::int64_t>(spans.size()), threads,
      [&](std::int64_t begin, std::int64_t end) {
        for (std::int64_t i = begin; i < end; ++i)
          crcs[i] = crc32(crc32(0L, Z_NULL, 0), spans[i].first, static_cast<uInt>(spans[i].second));
      },
      1);
  uLong crc = crc32(0L, Z_NULL, 0);
  for (std::size_t i = 0; i < spans.size(); ++i)
    crc = crc32_combine(crc, crcs[i], static_cast<z_off_t>(spans[i].second));
  return static_cast<std::uint32_t>(crc);
}

}  // namespace repose
