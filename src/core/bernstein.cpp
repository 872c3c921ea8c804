#include "seam/core/bernstein.h"

#include "core/bernstein_internal.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <optional>
#include <type_traits>
#include <vector>

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace seam {

namespace {
// Pascal's triangle up to kBinomialTableSize - 1 (exact in double far beyond that size).
constexpr int kBinomialTableSize = 128;
/// Built at compile time (no function-local static guard on the hot path of every Bernstein product).
struct BinomialTable {
  std::array<double, static_cast<size_t>(kBinomialTableSize * kBinomialTableSize)> v{};
  constexpr BinomialTable() {
    for (int n = 0; n < kBinomialTableSize; ++n) {
      v[static_cast<size_t>(n * kBinomialTableSize)] = 1.0;
      for (int k = 1; k <= n; ++k)
        v[static_cast<size_t>(n * kBinomialTableSize + k)] =
            v[static_cast<size_t>((n - 1) * kBinomialTableSize + k - 1)] +
            (k <= n - 1 ? v[static_cast<size_t>((n - 1) * kBinomialTableSize + k)] : 0.0);
    }
  }
};
constexpr BinomialTable kBinomials{};
}  // namespace

namespace {
/// Rows n >= kBinomialTableSize up to this are kept per thread once computed (binomial() costs O(k) there, and the
/// products of the pcurve route's degree-200..500 polynomials ask for every C(n, k) of a row, product after product).
constexpr int kBinomialRowCacheMax = 2048;
const double* cachedBinomialRow(int n) {
  thread_local std::vector<std::vector<double>> rows;
  const size_t i = static_cast<size_t>(n - kBinomialTableSize);
  if (rows.size() <= i) rows.resize(i + 1);
  std::vector<double>& row = rows[i];
  if (row.empty()) {
    row.resize(static_cast<size_t>(n) + 1);
    for (int k = 0; k <= n; ++k) row[static_cast<size_t>(k)] = binomial(n, k);  // the same values, once
  }
  return row.data();
}
// binomial() for this file's loops: the table look-up inlined (binomial() itself is out of line); rows above the
// table from the per-thread cache (the values of binomial(), bit for bit).
inline double binom(int n, int k) {
  if (k >= 0 && k <= n && n < kBinomialTableSize) return kBinomials.v[static_cast<size_t>(n * kBinomialTableSize + k)];
  if (k >= 0 && k <= n && n <= kBinomialRowCacheMax) return cachedBinomialRow(n)[k];
  return binomial(n, k);
}
}  // namespace

double binomial(int n, int k) {
  if (k < 0 || k > n) return 0.0;
  if (n < kBinomialTableSize) {
    return kBinomials.v[static_cast<size_t>(n * kBinomialTableSize + k)];
  }
  k = std::min(k, n - k);
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return std::round(r);
}

namespace {

/// Largest number of coefficient values (rows x columns) de Casteljau evaluates on the stack.
constexpr Eigen::Index kDeCasteljauStackSize = 256;

// x86-64: the de Casteljau and product loops are also compiled for AVX2 and chosen at run time (4 lanes instead of
// SSE2's 2). The same IEEE operations on every value in the same order (no FMA: -ffp-contract=off, and the AVX2
// target does not include FMA), so the results are bit for bit those of the SSE2 code.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define SEAM_BERNSTEIN_AVX2 1
#define SEAM_AVX2_TARGET [[gnu::target("avx2")]]
bool hasAvx2() {
  static const bool v = __builtin_cpu_supports("avx2");
  return v;
}
#else
constexpr bool hasAvx2() { return false; }
#endif
#define SEAM_KERNEL [[gnu::always_inline]] inline

// A SEAM_KERNEL compiled twice from its one source: for the baseline instruction set (SSE2) and, in builds with
// SEAM_BERNSTEIN_AVX2, for AVX2. run(wide, args...) takes the AVX2 copy when `wide` (the loops are long enough for
// four lanes to pay) and the CPU has AVX2.
template <auto kernel>
struct Avx2OrBaseline {
  template <class... Args>
  [[gnu::noinline]] static void baseline(Args... args) {
    kernel(args...);
  }
#ifdef SEAM_BERNSTEIN_AVX2
  template <class... Args>
  [[gnu::noinline]] SEAM_AVX2_TARGET static void avx2(Args... args) {
    kernel(args...);
  }
#endif
  template <class... Args>
  static void run([[maybe_unused]] bool wide, Args... args) {
#ifdef SEAM_BERNSTEIN_AVX2
    if (wide && hasAvx2()) return avx2(args...);
#endif
    baseline(args...);
  }
};

// The de Casteljau levels on w (n rows of d values), leaving the value in the first row.
SEAM_KERNEL void deCasteljauLevelsKernel(double* w, Eigen::Index n, Eigen::Index d, double t) {
  const double s = 1.0 - t;
  // The common widths with a compile-time inner loop.
  const auto levels = [&]<int kD>(std::integral_constant<int, kD>) {
    const Eigen::Index dd = kD > 0 ? kD : d;
    for (Eigen::Index r = 1; r < n; ++r)
      for (Eigen::Index i = 0; i < n - r; ++i) {
        double* x = w + i * dd;
        const double* y = x + dd;
        for (Eigen::Index k = 0; k < dd; ++k) x[k] = s * x[k] + t * y[k];
      }
  };
  switch (d) {
    case 1: levels(std::integral_constant<int, 1>{}); break;
    case 3: levels(std::integral_constant<int, 3>{}); break;
    case 4: levels(std::integral_constant<int, 4>{}); break;
    default: levels(std::integral_constant<int, 0>{}); break;
  }
}
#ifdef SEAM_BERNSTEIN_AVX2
constexpr Eigen::Index kSubdivideScalarAvx2MinDegree = 64;
// detail::splitHalves four lanes wide from this degree: at t = 1/2 the four-lane levels were as fast as element by
// element at degree 32-63 and 1.2-5x faster above (2026-11-27, one-off timing of both builds, degrees 32-480).
constexpr Eigen::Index kSplitHalvesAvx2MinDegree = 32;
void subdivideScalarAvx2(double* c, Eigen::Index n, double t, bool keepLeft, double* leftOut = nullptr);
#endif
void deCasteljauLevels(double* w, Eigen::Index n, Eigen::Index d, double t) {
#ifdef SEAM_BERNSTEIN_AVX2
  // One column: the levels are those of the subdivision keeping [t, 1] (w[i] = s w[i] + t w[i + 1]); at high degree
  // its explicit four-lane loop (the same operations per value).
  if (d == 1 && n - 1 >= kSubdivideScalarAvx2MinDegree && hasAvx2()) return subdivideScalarAvx2(w, n - 1, t, false);
#endif
  Avx2OrBaseline<deCasteljauLevelsKernel>::run(n > 8, w, n, d, t);
}

// Runs de Casteljau on the rows of `c` (copied) at t; returns the final row. The same s * a + t * b per value as
// row expressions, on a stack copy for small polynomials (no allocation but the result).
VecX deCasteljau(const Matrix& c, double t) {
  const auto n = c.rows();
  const auto d = c.cols();
  if (n == 0) return VecX::Zero(d);
  double stack[kDeCasteljauStackSize];
  std::vector<double> heap;
  double* w = stack;
  if (c.size() > kDeCasteljauStackSize) {
    heap.resize(static_cast<size_t>(c.size()));
    w = heap.data();
  }
  std::copy(c.data(), c.data() + c.size(), w);
  deCasteljauLevels(w, n, d, t);
  return Eigen::Map<const VecX>(w, d);
}

// Blossom of the polynomial with coefficient rows c at the arguments args (size = degree).
Eigen::RowVectorXd blossom(const Matrix& c, const std::vector<double>& args) {
  Matrix w = c;
  const auto n = c.rows();
  for (Eigen::Index r = 1; r < n; ++r) {
    const double t = args[static_cast<size_t>(r - 1)];
    for (Eigen::Index i = 0; i < n - r; ++i) w.row(i) = (1.0 - t) * w.row(i) + t * w.row(i + 1);
  }
  return w.row(0);
}

// Weighted Cauchy product of Bernstein coefficient rows: out_k = sum_{i+j=k} C(n,i)C(m,j)/C(n+m,k) a_i * b_j
// where "*" is the elementwise product of the rows (a broadcast when one of them has one column).
// Products with n + m above kPow2ScaledProductMaxDegree use the per-term weights C(n,i) C(m,j) / C(n+m,i+j); below
// it the scaled form (rows multiplied by C(n,i), C(m,j), convolved, divided by C(n+m,k)), which saves the per-term
// divisions. Up to kScaledProductMaxDegree the binomials as they are: C(500,250) ~ 1e149, so the scaled
// coefficients stay far inside the double range. Above it (the pcurve route's compositions on real B-reps reach
// degree 300-750) the binomial rows are first divided by powers of two, 2^-e_n and 2^-e_m with e_n the exponent of
// C(n, n/2), and the divisors C(n+m,k) by 2^(e_n + e_m): the same products up to that exact power of two (no
// rounding of its own), so the scaled rows stay near the coefficients' size; C(1000,500) ~ 2.7e299 bounds the rows
// and 2^-(e_n + e_m) >= 2^-1000 keeps the divisors normal.
constexpr int kScaledProductMaxDegree = 500;
constexpr int kPow2ScaledProductMaxDegree = 1000;

// so[i + j] += sa[i] * sb[j], i outer (each so[k] sums its terms in the order of i).
SEAM_KERNEL void convolveAddKernel(const double* sa, int n, const double* sb, int m, double* so) {
  for (int i = 0; i <= n; ++i) {
    const double x = sa[i];
    for (int j = 0; j <= m; ++j) so[i + j] += x * sb[j];
  }
}
void convolveAdd(const double* sa, int n, const double* sb, int m, double* so) {
  Avx2OrBaseline<convolveAddKernel>::run(m > 8, sa, n, sb, m, so);
}

// The binomial row C(n, 0..n) for n <= kBinomialRowCacheMax: the table's row or the per-thread cached one.
inline const double* binomialRow(int n) {
  if (n < kBinomialTableSize) return &kBinomials.v[static_cast<size_t>(n * kBinomialTableSize)];
  return cachedBinomialRow(n);
}

// The binomial rows of a product of degrees n and m in the scaled form (see kPow2ScaledProductMaxDegree): C(n, i),
// C(m, j) and the divisors C(n + m, k), as they are up to kScaledProductMaxDegree, divided by 2^e_n, 2^e_m and
// 2^(e_n + e_m) above (exact: ldexp of values >= 1 that stay normal). Valid until the next call on the thread.
struct ProductBinomials {
  const double *bn, *bm, *bnm;
};
ProductBinomials productBinomials(int n, int m) {
  const double *bn = binomialRow(n), *bm = binomialRow(m), *bnm = binomialRow(n + m);
  if (n + m <= kScaledProductMaxDegree) return {bn, bm, bnm};
  assert(n + m <= kPow2ScaledProductMaxDegree);
  thread_local std::vector<double> rows;
  const size_t sn = static_cast<size_t>(n) + 1, sm = static_cast<size_t>(m) + 1;
  rows.resize(sn + sm + static_cast<size_t>(n + m) + 1);
  const int en = std::ilogb(bn[n / 2]), em = std::ilogb(bm[m / 2]);
  for (size_t i = 0; i < sn; ++i) rows[i] = std::ldexp(bn[i], -en);
  for (size_t j = 0; j < sm; ++j) rows[sn + j] = std::ldexp(bm[j], -em);
  for (int k = 0; k <= n + m; ++k) rows[sn + sm + static_cast<size_t>(k)] = std::ldexp(bnm[k], -(en + em));
  return {rows.data(), rows.data() + sn, rows.data() + sn + sm};
}

// out[(i + j) * d + c] += sa(i, c) * sb(j, c) over i (outer), j, c on row-major rows of d values; an operand with
// one column (aScalar / bScalar) is broadcast: sa(i, c) = sa[i], sb(j, c) = sb[j]. Each output value sums its terms in
// the order of i, as convolveAdd does column by column, and the products commute exactly: the same bits.
template <int kD>
SEAM_KERNEL void convolveRowsKernel(const double* sa, bool aScalar, int n, const double* sb, bool bScalar, int m,
                                    Eigen::Index d, double* so) {
  const Eigen::Index dd = kD > 0 ? kD : d;
  for (int i = 0; i <= n; ++i) {
    double* o = so + static_cast<Eigen::Index>(i) * dd;
    if (aScalar) {
      const double x = sa[i];
      for (Eigen::Index q = 0; q < static_cast<Eigen::Index>(m + 1) * dd; ++q) o[q] += x * sb[q];
    } else if (bScalar) {
      const double* x = sa + static_cast<Eigen::Index>(i) * dd;
      for (int j = 0; j <= m; ++j) {
        const double y = sb[j];
        for (Eigen::Index c = 0; c < dd; ++c) o[j * dd + c] += x[c] * y;
      }
    } else {
      const double* x = sa + static_cast<Eigen::Index>(i) * dd;
      for (int j = 0; j <= m; ++j)
        for (Eigen::Index c = 0; c < dd; ++c) o[j * dd + c] += x[c] * sb[j * dd + c];
    }
  }
}
SEAM_KERNEL void convolveRowsDispatch(const double* sa, bool aScalar, int n, const double* sb, bool bScalar, int m,
                                      Eigen::Index d, double* so) {
  switch (d) {
    case 3: return convolveRowsKernel<3>(sa, aScalar, n, sb, bScalar, m, d, so);
    case 4: return convolveRowsKernel<4>(sa, aScalar, n, sb, bScalar, m, d, so);
    default: return convolveRowsKernel<0>(sa, aScalar, n, sb, bScalar, m, d, so);
  }
}
void convolveRows(const double* sa, bool aScalar, int n, const double* sb, bool bScalar, int m, Eigen::Index d,
                  double* so) {
  Avx2OrBaseline<convolveRowsDispatch>::run(true, sa, aScalar, n, sb, bScalar, m, d, so);
}

// so_c[i + j] += (x_i cross y_j)_c for the rows x_i of sa (row-major, 3 values) and y_j of B, i outer: B and the sums
// by column (sb_c[j] = sb[c (m + 1) + j], so_c[k] = so[c (n + m + 1) + k]), so that the loop over j runs four lanes
// wide. Each term is Eigen's Vector3d::cross (x1 y2 - x2 y1, x2 y0 - x0 y2, x0 y1 - x1 y0) and each sum adds its
// terms in the order of i, as the row-by-row loop did: the same bits.
SEAM_KERNEL void crossRowsKernel(const double* sa, int n, const double* sb, int m, double* so) {
  const size_t nb = static_cast<size_t>(m) + 1, no = static_cast<size_t>(n + m) + 1;
  const double *y0 = sb, *y1 = sb + nb, *y2 = sb + 2 * nb;
  for (int i = 0; i <= n; ++i) {
    const double x0 = sa[3 * i], x1 = sa[3 * i + 1], x2 = sa[3 * i + 2];
    double* __restrict o0 = so + i;
    double* __restrict o1 = so + no + i;
    double* __restrict o2 = so + 2 * no + i;
    for (size_t j = 0; j < nb; ++j) {
      o0[j] += x1 * y2[j] - x2 * y1[j];
      o1[j] += x2 * y0[j] - x0 * y2[j];
      o2[j] += x0 * y1[j] - x1 * y0[j];
    }
  }
}
void crossRows(const double* sa, int n, const double* sb, int m, double* so) {
  Avx2OrBaseline<crossRowsKernel>::run(m > 8, sa, n, sb, m, so);
}

// productRows of an A with several columns goes column by column from this degree of A (and B above degree 8, where
// convolveAdd runs four lanes wide); below, the row-major convolution (convolveRows).
constexpr int kColumnProductMinDegree = 4;

Matrix productRows(const Matrix& a, const Matrix& b) {
  const int n = static_cast<int>(a.rows()) - 1;
  const int m = static_cast<int>(b.rows()) - 1;
  const auto dim = std::max(a.cols(), b.cols());
  Matrix out = Matrix::Zero(n + m + 1, dim);
  if (n + m <= kPow2ScaledProductMaxDegree && dim == 1) {
    // One column: a contiguous scaled copy of each row set, convolved, divided by C(n + m, k).
    double sa[kPow2ScaledProductMaxDegree + 1], sb[kPow2ScaledProductMaxDegree + 1];
    const auto [bn, bmr, bnm] = productBinomials(n, m);
    for (int i = 0; i <= n; ++i) sa[i] = a(i, 0) * bn[i];
    for (int j = 0; j <= m; ++j) sb[j] = b(j, 0) * bmr[j];
    double* so = out.data();
    convolveAdd(sa, n, sb, m, so);
    for (int k = 0; k <= n + m; ++k) so[k] = so[k] / bnm[k];
    return out;
  }
  if (n + m <= kPow2ScaledProductMaxDegree) {
    // All columns at once on the row-major rows (a one-column operand scaled once and broadcast): per value the
    // same products, sums in the same order and the same division as column by column.
    const auto [bn, bmr, bnm] = productBinomials(n, m);
    constexpr size_t kStack = 2048;
    double stackA[kStack], stackB[kStack];
    std::vector<double> heapA, heapB;
    double* sa = stackA;
    double* sb = stackB;
    if (static_cast<size_t>(a.size()) > kStack) {
      heapA.resize(static_cast<size_t>(a.size()));
      sa = heapA.data();
    }
    if (static_cast<size_t>(b.size()) > kStack) {
      heapB.resize(static_cast<size_t>(b.size()));
      sb = heapB.data();
    }
    const Eigen::Index ca = a.cols(), cb = b.cols();
    for (int i = 0; i <= n; ++i)
      for (Eigen::Index c = 0; c < ca; ++c) sa[i * ca + c] = a(i, c) * bn[i];
    for (int j = 0; j <= m; ++j)
      for (Eigen::Index c = 0; c < cb; ++c) sb[j * cb + c] = b(j, c) * bmr[j];
    double* so = out.data();
    if (ca > 1 && n >= kColumnProductMinDegree && m > 8) {
      // A with several columns: column by column through contiguous copies (convolveAdd, four lanes over j; the
      // row-major rows of 3 or 4 values do not fill the lanes). Per value the same products summed in the order of
      // i from the same zero: the same bits as convolveRows.
      thread_local std::vector<double> columns;
      columns.resize(static_cast<size_t>(2 * (n + m) + 3));
      double* xa = columns.data();
      double* xb = xa + n + 1;
      double* xo = xb + m + 1;
      for (Eigen::Index c = 0; c < dim; ++c) {
        for (int i = 0; i <= n; ++i) xa[i] = sa[i * ca + c];
        const double* yb = sb;
        if (cb > 1) {
          for (int j = 0; j <= m; ++j) xb[j] = sb[j * cb + c];
          yb = xb;
        }
        std::fill(xo, xo + n + m + 1, 0.0);
        convolveAdd(xa, n, yb, m, xo);
        for (int k = 0; k <= n + m; ++k) so[k * dim + c] = xo[k];
      }
    } else {
      convolveRows(sa, ca == 1, n, sb, cb == 1, m, dim, so);
    }
    for (int k = 0; k <= n + m; ++k)
      for (Eigen::Index c = 0; c < dim; ++c) so[k * dim + c] = so[k * dim + c] / bnm[k];
    return out;
  }
  // The binomials once per row (above the table they cost O(k) each; per pair they dominated high degrees).
  std::vector<double> bm(static_cast<size_t>(m) + 1), bnm(static_cast<size_t>(n + m) + 1);
  for (int j = 0; j <= m; ++j) bm[static_cast<size_t>(j)] = binom(m, j);
  for (int k = 0; k <= n + m; ++k) bnm[static_cast<size_t>(k)] = binom(n + m, k);
  for (int i = 0; i <= n; ++i) {
    const double bi = binom(n, i);
    for (int j = 0; j <= m; ++j) {
      const double f = bi * bm[static_cast<size_t>(j)] / bnm[static_cast<size_t>(i + j)];
      if (a.cols() == b.cols()) {
        out.row(i + j).array() += f * a.row(i).array() * b.row(j).array();
      } else if (a.cols() == 1) {
        out.row(i + j) += (f * a(i, 0)) * b.row(j);
      } else {
        out.row(i + j) += (f * b(j, 0)) * a.row(i);
      }
    }
  }
  return out;
}

// The polynomial de Casteljau levels b_i <- product(A, b_i) + product(B, b_{i+1}) (A, B scalar of the same degree k)
// on n + 1 polynomials b_0..b_n of degree m0 and d columns, stacked in `rows` ((n + 1)(m0 + 1) x d); the result is
// the last level's b_0 (degree m0 + n k). Without temporaries: each b_j is scaled by its binomials once per level
// (it serves as b_i of one term and b_{i+1} of another) and both products' convolutions run on scratch rows, with
// the same values, sums in the same order, divisions and final sum as productRows and operator+: the same bits.
// nullopt when a product would leave productRows' scaled form (m0 + n k > kScaledProductMaxDegree) or when A and B
// differ in degree: the caller then uses the products themselves.
std::optional<Matrix> lerpLevels(const Matrix& rows, int n, int m0, const Matrix& A, const Matrix& B) {
  const int k = static_cast<int>(A.rows()) - 1;
  if (B.rows() != A.rows() || A.cols() != 1 || B.cols() != 1 || m0 + n * k > kScaledProductMaxDegree) return std::nullopt;
  const Eigen::Index d = rows.cols();
  if (n == 0) return Matrix(rows.topRows(m0 + 1));
  const Eigen::Index stride = static_cast<Eigen::Index>(m0 + n * k + 1) * d;
  const size_t slots = static_cast<size_t>(n) + 1;
  // Per-thread scratch (grown, never shrunk): every value is written before it is read.
  thread_local std::vector<double> buf, scaled, t1, t2, sa;
  buf.resize(slots * static_cast<size_t>(stride));
  scaled.resize(buf.size());
  t1.resize(static_cast<size_t>(stride));
  t2.resize(static_cast<size_t>(stride));
  sa.resize(2 * (static_cast<size_t>(k) + 1));
  for (size_t j = 0; j < slots; ++j)
    std::copy(rows.data() + static_cast<Eigen::Index>(j) * (m0 + 1) * d,
              rows.data() + static_cast<Eigen::Index>(j + 1) * (m0 + 1) * d, buf.data() + j * stride);
  const double* bk = binomialRow(k);
  double* sa1 = sa.data();
  double* sa2 = sa.data() + k + 1;
  for (int i = 0; i <= k; ++i) {
    sa1[i] = A(i, 0) * bk[i];
    sa2[i] = B(i, 0) * bk[i];
  }
  int m = m0;
  for (int r = 1; r <= n; ++r) {
    const double* bm = binomialRow(m);
    const double* bo = binomialRow(m + k);
    const Eigen::Index outSize = static_cast<Eigen::Index>(m + k + 1) * d;
    for (int j = 0; j <= n - r + 1; ++j) {
      const double* x = buf.data() + j * stride;
      double* y = scaled.data() + j * stride;
      for (int q = 0; q <= m; ++q)
        for (Eigen::Index c = 0; c < d; ++c) y[q * d + c] = x[q * d + c] * bm[q];
    }
    for (int i = 0; i <= n - r; ++i) {
      std::fill(t1.begin(), t1.begin() + outSize, 0.0);
      std::fill(t2.begin(), t2.begin() + outSize, 0.0);
      convolveRows(sa1, true, k, scaled.data() + i * stride, d == 1, m, d, t1.data());
      convolveRows(sa2, true, k, scaled.data() + (i + 1) * stride, d == 1, m, d, t2.data());
      double* o = buf.data() + i * stride;
      for (int q = 0; q <= m + k; ++q)
        for (Eigen::Index c = 0; c < d; ++c) o[q * d + c] = t1[q * d + c] / bo[q] + t2[q * d + c] / bo[q];
    }
    m += k;
  }
  return Matrix(Eigen::Map<const Matrix>(buf.data(), m + 1, d));
}

Matrix elevateRows(const Matrix& c, int by) {
  if (by <= 0) return c;
  const int n = static_cast<int>(c.rows()) - 1;
  Matrix out = Matrix::Zero(n + by + 1, c.cols());
  // The binomial rows C(n, .), C(by, .) and C(n + by, .): binomialRow's within its cache, else filled from binom (the
  // same values either way). Per value the factor C(n, j) C(by, i - j) / C(n + by, i) times row j, summed over j.
  std::vector<double> ownN, ownBy, ownOut;
  auto row = [](int m, std::vector<double>& own) -> const double* {
    if (m <= kBinomialRowCacheMax) return binomialRow(m);
    own.resize(static_cast<size_t>(m) + 1);
    for (int k = 0; k <= m; ++k) own[static_cast<size_t>(k)] = binom(m, k);
    return own.data();
  };
  const double *bn = row(n, ownN), *bb = row(by, ownBy), *bo = row(n + by, ownOut);
  const Eigen::Index d = c.cols();
  for (int i = 0; i <= n + by; ++i) {
    const double denom = bo[i];
    double* o = out.data() + static_cast<Eigen::Index>(i) * d;
    for (int j = std::max(0, i - by); j <= std::min(n, i); ++j) {
      const double f = bn[j] * bb[i - j] / denom;
      const double* x = c.data() + static_cast<Eigen::Index>(j) * d;
      for (Eigen::Index k = 0; k < d; ++k) o[k] += f * x[k];
    }
  }
  return out;
}

Matrix derivativeRows(const Matrix& c, int order) {
  Matrix cur = c;
  for (int k = 0; k < order; ++k) {
    const int n = static_cast<int>(cur.rows()) - 1;
    if (n <= 0) return Matrix::Zero(1, c.cols());
    Matrix next(n, cur.cols());
    for (int i = 0; i < n; ++i) next.row(i) = n * (cur.row(i + 1) - cur.row(i));
    cur = std::move(next);
  }
  return cur;
}

// In place, on the row-major coefficients (n + 1 rows of d values) directly: the per-row Eigen expressions on dynamic rows
// cost more than the arithmetic. After the call, c holds the coefficients of the piece on [0, t] (keepLeft) or
// [t, 1]; the same s * a + t * b per coefficient as the row expressions it replaces, so the same bits.
SEAM_KERNEL void subdivideKernel(double* c, Eigen::Index n, Eigen::Index d, double t, bool keepLeft) {
  const double s = 1.0 - t;
  if (d == 1) {
    if (keepLeft) {
      // left_r = first row after r levels; computing from the bottom keeps earlier rows intact.
      for (Eigen::Index r = 1; r <= n; ++r)
        for (Eigen::Index i = n; i >= r; --i) c[i] = s * c[i - 1] + t * c[i];
    } else {
      for (Eigen::Index r = 1; r <= n; ++r)
        for (Eigen::Index i = 0; i <= n - r; ++i) c[i] = s * c[i] + t * c[i + 1];
    }
    return;
  }
  if (keepLeft) {
    for (Eigen::Index r = 1; r <= n; ++r)
      for (Eigen::Index i = n; i >= r; --i) {
        double* x = c + i * d;
        const double* y = x - d;
        for (Eigen::Index k = 0; k < d; ++k) x[k] = s * y[k] + t * x[k];
      }
  } else {
    for (Eigen::Index r = 1; r <= n; ++r)
      for (Eigen::Index i = 0; i <= n - r; ++i) {
        double* x = c + i * d;
        const double* y = x + d;
        for (Eigen::Index k = 0; k < d; ++k) x[k] = s * x[k] + t * y[k];
      }
  }
}
// Scalar polynomials (d = 1: the certified bounds restrict P, Q, R, ... thousands of times per seam) without
// vectorisation: each level reads the values the level before has just stored, one coefficient over, so vector loads
// straddle the previous level's vector stores and stall on store forwarding; element by element it runs 1.3-2.4x
// faster (degrees 10-36; issue 13 §2). The same operations per coefficient, so the same bits.
#if defined(__GNUC__) && !defined(__clang__)
[[gnu::optimize("no-tree-vectorize")]]
#endif
void subdivideScalar(double* c, Eigen::Index n, double t, bool keepLeft, double* leftOut = nullptr) {
  const double s = 1.0 - t;
  if (keepLeft) {
    for (Eigen::Index r = 1; r <= n; ++r)
#if defined(__clang__)
#pragma clang loop vectorize(disable)
#endif
      for (Eigen::Index i = n; i >= r; --i) c[i] = s * c[i - 1] + t * c[i];
  } else {
    for (Eigen::Index r = 1; r <= n; ++r) {
#if defined(__clang__)
#pragma clang loop vectorize(disable)
#endif
      for (Eigen::Index i = 0; i <= n - r; ++i) c[i] = s * c[i] + t * c[i + 1];
      if (leftOut != nullptr) leftOut[r] = c[0];  // the left part's coefficient r (detail::splitHalves)
    }
  }
}
#ifdef SEAM_BERNSTEIN_AVX2
// Scalar polynomials of high degree (the pcurve route's P, Q, R of degree 100..500, restricted thousands of times by
// the bound subdivision): four coefficients of a level at a time. The previous level's stores that a vector load
// straddles are a whole level (>= kSubdivideScalarAvx2MinDegree coefficients) back, long retired, so the stall that
// keeps low degrees element by element (subdivideScalar) does not occur; 4-5x faster at degrees 128-480. Per
// coefficient the same s * a + t * b as subdivideScalar (two products, then their sum; no FMA), in an order in which
// every value read is the previous level's: the same bits.
SEAM_AVX2_TARGET void subdivideScalarAvx2(double* c, Eigen::Index n, double t, bool keepLeft, double* leftOut) {
  const double s = 1.0 - t;
  const __m256d vs = _mm256_set1_pd(s), vt = _mm256_set1_pd(t);
  if (keepLeft) {
    // Descending: c[i-3..i] from c[i-4..i] (both loaded before the store; the next block down reads only values
    // this level has not yet written).
    for (Eigen::Index r = 1; r <= n; ++r) {
      Eigen::Index i = n;
      for (; i - 3 >= r; i -= 4) {
        const __m256d x = _mm256_loadu_pd(c + i - 4), y = _mm256_loadu_pd(c + i - 3);
        _mm256_storeu_pd(c + i - 3, _mm256_add_pd(_mm256_mul_pd(vs, x), _mm256_mul_pd(vt, y)));
      }
      for (; i >= r; --i) c[i] = s * c[i - 1] + t * c[i];
    }
  } else {
    for (Eigen::Index r = 1; r <= n; ++r) {
      const Eigen::Index last = n - r;
      Eigen::Index i = 0;
      for (; i + 3 <= last; i += 4) {
        const __m256d x = _mm256_loadu_pd(c + i), y = _mm256_loadu_pd(c + i + 1);
        _mm256_storeu_pd(c + i, _mm256_add_pd(_mm256_mul_pd(vs, x), _mm256_mul_pd(vt, y)));
      }
      for (; i <= last; ++i) c[i] = s * c[i] + t * c[i + 1];
      if (leftOut != nullptr) leftOut[r] = c[0];  // the left part's coefficient r (detail::splitHalves)
    }
  }
}
#endif
void subdivideInPlace(double* c, Eigen::Index n, Eigen::Index d, double t, bool keepLeft) {
#ifdef SEAM_BERNSTEIN_AVX2
  if (d == 1 && n >= kSubdivideScalarAvx2MinDegree && hasAvx2()) return subdivideScalarAvx2(c, n, t, keepLeft);
#endif
  if (d == 1) return subdivideScalar(c, n, t, keepLeft);
  Avx2OrBaseline<subdivideKernel>::run(n > 8, c, n, d, t, keepLeft);
}
void subdivideInPlace(Matrix& w, double t, bool keepLeft) { subdivideInPlace(w.data(), w.rows() - 1, w.cols(), t, keepLeft); }

Matrix restrictRows(const Matrix& c, double a, double b) {
  const int n = static_cast<int>(c.rows()) - 1;
  if (a == 0.0 && b == 1.0) return c;
  if (a > b && a <= 1.0 && b >= 0.0) return restrictRows(c, b, a).colwise().reverse();
  if (a >= 0.0 && a < b && b <= 1.0) {
    // Two de Casteljau subdivisions: keep [0, b], then the part [a/b, 1] of it.
    Matrix w = c;
    if (b < 1.0) subdivideInPlace(w, b, true);
    if (a > 0.0) subdivideInPlace(w, a / b, false);
    return w;
  }
  // General intervals (outside [0,1]): blossoms q_i = p[a^(n-i), b^i].
  Matrix out(c.rows(), c.cols());
  std::vector<double> args(static_cast<size_t>(n));
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k < n; ++k) args[static_cast<size_t>(k)] = k < n - i ? a : b;
    out.row(i) = blossom(c, args);
  }
  return out;
}

}  // namespace

namespace detail {
// Both halves of one de Casteljau triangle at 1/2: the right-keeping levels of subdivideScalar / subdivideKernel
// (row i <- (row i + row i+1) / 2, as 0.5 a + 0.5 b: both products exact, one rounding, no overflow near the largest
// doubles), with each level's first row recorded as the left half's next coefficient.
void splitHalves(const double* c, Eigen::Index n, Eigen::Index d, double* left, double* right) {
  std::copy(c, c + (n + 1) * d, right);
  std::copy(c, c + d, left);
  // One column: the right-keeping levels of subdivideScalar(Avx2) at t = 1/2 (s = 1 - t = 1/2 exactly, so each
  // value is 0.5 a + 0.5 b), recording each level's first value.
#ifdef SEAM_BERNSTEIN_AVX2
  if (d == 1 && n >= kSplitHalvesAvx2MinDegree && hasAvx2()) return subdivideScalarAvx2(right, n, 0.5, false, left);
#endif
  if (d == 1) return subdivideScalar(right, n, 0.5, false, left);
  for (Eigen::Index r = 1; r <= n; ++r) {
    for (Eigen::Index i = 0; i <= n - r; ++i)
      for (Eigen::Index k = 0; k < d; ++k) right[i * d + k] = 0.5 * right[i * d + k] + 0.5 * right[(i + 1) * d + k];
    std::copy(right, right + d, left + r * d);
  }
}

Eigen::Map<const Matrix> restrictedCoeffs(const BernsteinPoly& p, double a, double b, std::vector<double>& scratch) {
  const Matrix& c = p.coeffs();
  if (a == 0.0 && b == 1.0) return {c.data(), c.rows(), c.cols()};
  const size_t size = static_cast<size_t>(c.size());
  if (scratch.size() < size) scratch.resize(size);
  if (a >= 0.0 && a < b && b <= 1.0) {
    // As restrictRows: keep [0, b], then the part [a/b, 1] of it.
    std::copy(c.data(), c.data() + size, scratch.data());
    if (b < 1.0) subdivideInPlace(scratch.data(), c.rows() - 1, c.cols(), b, true);
    if (a > 0.0) subdivideInPlace(scratch.data(), c.rows() - 1, c.cols(), a / b, false);
  } else {
    const Matrix r = restrictRows(c, a, b);
    std::copy(r.data(), r.data() + size, scratch.data());
  }
  return {scratch.data(), c.rows(), c.cols()};
}

CertifiedMin certifiedMinimum(const BernsteinPoly& p, double tolAbs, int maxDepth) {
  CertifiedMin r;
  r.lower = r.attained = std::numeric_limits<double>::infinity();
  if (p.empty()) return r;
  struct Item {
    BernsteinPoly q;
    double lo, hi;
    int depth;
  };
  std::vector<Item> stack{{p, 0.0, 1.0, 0}};
  while (!stack.empty()) {
    Item it = std::move(stack.back());
    stack.pop_back();
    const Eigen::VectorXd c = it.q.coeffs().col(0);
    // The end coefficients are values of p: candidates for the attained minimum.
    if (c[0] < r.attained) { r.attained = c[0]; r.at = it.lo; }
    if (c[c.size() - 1] < r.attained) { r.attained = c[c.size() - 1]; r.at = it.hi; }
    const double bound = c.minCoeff();  // convex hull: p >= bound on this piece
    if (bound >= r.attained - tolAbs || it.depth >= maxDepth) {
      r.lower = std::min(r.lower, bound);
      continue;
    }
    auto [left, right] = it.q.subdivided(0.5);
    const double mid = 0.5 * (it.lo + it.hi);
    stack.push_back({std::move(right), mid, it.hi, it.depth + 1});
    stack.push_back({std::move(left), it.lo, mid, it.depth + 1});
  }
  r.lower = std::min(r.lower, r.attained);
  return r;
}
}  // namespace detail

namespace {

// View of a patch as a curve in u whose coefficients are whole v-rows: (n+1) x ((m+1)*dim).
Matrix uRows(const BernsteinPatch& p) {
  return Eigen::Map<const Matrix>(p.coeffs().data(), p.degreeU() + 1, (p.degreeV() + 1) * p.dim());
}
BernsteinPatch fromURows(const Matrix& rows, int degreeV, int dim) {
  const int du = static_cast<int>(rows.rows()) - 1;
  Matrix c = Eigen::Map<const Matrix>(rows.data(), (du + 1) * (degreeV + 1), dim);
  return BernsteinPatch(du, degreeV, std::move(c));
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// BernsteinPoly

BernsteinPoly::BernsteinPoly(Matrix coefficients) : c_(std::move(coefficients)) {}

BernsteinPoly BernsteinPoly::zero(int degree, int dim) { return BernsteinPoly(Matrix::Zero(degree + 1, dim)); }

BernsteinPoly BernsteinPoly::constant(const VecX& value, int degree) {
  Matrix c(degree + 1, value.size());
  for (int i = 0; i <= degree; ++i) c.row(i) = value.transpose();
  return BernsteinPoly(std::move(c));
}

BernsteinPoly BernsteinPoly::constant(double value, int degree) {
  return BernsteinPoly(Matrix::Constant(degree + 1, 1, value));
}

BernsteinPoly BernsteinPoly::linear(double a, double b) {
  Matrix c(2, 1);
  c << a, b;
  return BernsteinPoly(std::move(c));
}

BernsteinPoly BernsteinPoly::fromPowerBasis(const VecX& a) {
  const int n = std::max<int>(0, static_cast<int>(a.size()) - 1);
  Matrix c = Matrix::Zero(n + 1, 1);
  for (int i = 0; i <= n; ++i)
    for (int k = 0; k <= i && k < a.size(); ++k) c(i, 0) += binom(i, k) / binom(n, k) * a[k];
  return BernsteinPoly(std::move(c));
}

VecX BernsteinPoly::operator()(double t) const { return deCasteljau(c_, t); }

// Unvectorised, as subdivideScalar (each level reads the previous level's stores one coefficient over): the same bits.
#if defined(__GNUC__) && !defined(__clang__)
[[gnu::optimize("no-tree-vectorize")]]
#endif
double BernsteinPoly::scalar(double t) const {
  assert(dim() == 1);
  const int n = degree();
  if (n < 0) return 0.0;
  // Scalar de Casteljau without allocation for degrees up to 63.
  double w[64];
  if (n < 64) {
    for (int i = 0; i <= n; ++i) w[i] = c_(i, 0);
    const double s = 1.0 - t;
    for (int r = 1; r <= n; ++r)
      for (int i = 0; i <= n - r; ++i) w[i] = s * w[i] + t * w[i + 1];
    return w[0];
  }
  return deCasteljau(c_, t)[0];
}

BernsteinPoly BernsteinPoly::derivative(int order) const { return BernsteinPoly(derivativeRows(c_, order)); }

BernsteinPoly BernsteinPoly::elevated(int by) const { return BernsteinPoly(elevateRows(c_, by)); }

BernsteinPoly BernsteinPoly::elevatedTo(int degree) const {
  assert(degree >= this->degree());
  return elevated(degree - this->degree());
}

std::pair<BernsteinPoly, BernsteinPoly> BernsteinPoly::subdivided(double t) const {
  const auto n = c_.rows();
  Matrix w = c_;
  Matrix left(n, c_.cols()), right(n, c_.cols());
  left.row(0) = w.row(0);
  right.row(n - 1) = w.row(n - 1);
  for (Eigen::Index r = 1; r < n; ++r) {
    for (Eigen::Index i = 0; i < n - r; ++i) w.row(i) = (1.0 - t) * w.row(i) + t * w.row(i + 1);
    left.row(r) = w.row(0);
    right.row(n - 1 - r) = w.row(n - 1 - r);
  }
  return {BernsteinPoly(std::move(left)), BernsteinPoly(std::move(right))};
}

BernsteinPoly BernsteinPoly::restricted(double a, double b) const { return BernsteinPoly(restrictRows(c_, a, b)); }

BernsteinPoly BernsteinPoly::reversed() const { return BernsteinPoly(c_.colwise().reverse()); }

BernsteinPoly BernsteinPoly::composed(const BernsteinPoly& w) const {
  assert(w.dim() == 1);
  const int n = degree();
  // de Casteljau with polynomial arithmetic: b_i <- (1 - w) b_i + w b_{i+1}; each level raises the degree by deg w.
  const BernsteinPoly oneMinusW = BernsteinPoly::constant(1.0, w.degree()) - w;
  if (std::optional<Matrix> c = lerpLevels(c_, n, 0, oneMinusW.coeffs(), w.coeffs())) return BernsteinPoly(std::move(*c));
  std::vector<BernsteinPoly> b;
  b.reserve(static_cast<size_t>(n + 1));
  for (int i = 0; i <= n; ++i) b.emplace_back(Matrix(c_.row(i)));
  for (int r = 1; r <= n; ++r)
    for (int i = 0; i <= n - r; ++i)
      b[static_cast<size_t>(i)] =
          product(oneMinusW, b[static_cast<size_t>(i)]) + product(w, b[static_cast<size_t>(i + 1)]);
  return b.front();
}

BernsteinPoly BernsteinPoly::component(int k) const { return BernsteinPoly(Matrix(c_.col(k))); }

VecX BernsteinPoly::minCoeff() const { return c_.colwise().minCoeff().transpose(); }
VecX BernsteinPoly::maxCoeff() const { return c_.colwise().maxCoeff().transpose(); }
double BernsteinPoly::maxAbsCoeff() const { return c_.size() ? c_.cwiseAbs().maxCoeff() : 0.0; }
double BernsteinPoly::maxCoeffNorm() const { return c_.size() ? c_.rowwise().norm().maxCoeff() : 0.0; }

BernsteinPoly& BernsteinPoly::operator*=(double s) {
  c_ *= s;
  return *this;
}

BernsteinPoly operator+(const BernsteinPoly& a, const BernsteinPoly& b) {
  assert(a.dim() == b.dim());
  const int n = std::max(a.degree(), b.degree());
  return BernsteinPoly(elevateRows(a.c_, n - a.degree()) + elevateRows(b.c_, n - b.degree()));
}

BernsteinPoly operator-(const BernsteinPoly& a, const BernsteinPoly& b) {
  assert(a.dim() == b.dim());
  const int n = std::max(a.degree(), b.degree());
  return BernsteinPoly(elevateRows(a.c_, n - a.degree()) - elevateRows(b.c_, n - b.degree()));
}

BernsteinPoly BernsteinPoly::operator-() const { return BernsteinPoly(-c_); }

BernsteinPoly product(const BernsteinPoly& a, const BernsteinPoly& b) {
  assert(a.dim() == b.dim() || a.dim() == 1 || b.dim() == 1);
  return BernsteinPoly(productRows(a.coeffs(), b.coeffs()));
}

BernsteinPoly dot(const BernsteinPoly& a, const BernsteinPoly& b) {
  assert(a.dim() == b.dim());
  Matrix p = productRows(a.coeffs(), b.coeffs());
  return BernsteinPoly(Matrix(p.rowwise().sum()));
}

BernsteinPoly cross(const BernsteinPoly& a, const BernsteinPoly& b) {
  assert(a.dim() == 3 && b.dim() == 3);
  const int n = a.degree(), m = b.degree();
  if (n + m > kPow2ScaledProductMaxDegree) {
    auto c = [&](int i, int j) { return product(a.component(i), b.component(j)); };
    const BernsteinPoly x = c(1, 2) - c(2, 1);
    const BernsteinPoly y = c(2, 0) - c(0, 2);
    const BernsteinPoly z = c(0, 1) - c(1, 0);
    Matrix out(x.coeffs().rows(), 3);
    out.col(0) = x.coeffs().col(0);
    out.col(1) = y.coeffs().col(0);
    out.col(2) = z.coeffs().col(0);
    return BernsteinPoly(std::move(out));
  }
  // One convolution of the binomially scaled rows (see productRows), B's rows and the sums by column (crossRows).
  const auto [bn, bmr, bnm] = productBinomials(n, m);
  Matrix as = a.coeffs(), bs = b.coeffs();
  for (int i = 0; i <= n; ++i) as.row(i) *= bn[i];
  for (int j = 0; j <= m; ++j) bs.row(j) *= bmr[j];
  thread_local std::vector<double> scratch;
  const size_t nb = static_cast<size_t>(m) + 1, no = static_cast<size_t>(n + m) + 1;
  scratch.assign(3 * (nb + no), 0.0);
  double* sb = scratch.data();
  double* so = sb + 3 * nb;
  for (size_t j = 0; j < nb; ++j)
    for (size_t c = 0; c < 3; ++c) sb[c * nb + j] = bs(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(c));
  crossRows(as.data(), n, sb, m, so);
  Matrix out(n + m + 1, 3);
  for (size_t k = 0; k < no; ++k)
    for (size_t c = 0; c < 3; ++c) out(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(c)) = so[c * no + k];
  for (int k = 0; k <= n + m; ++k) out.row(k) /= bnm[k];
  return BernsteinPoly(std::move(out));
}

BernsteinPoly triple(const BernsteinPoly& a, const BernsteinPoly& b, const BernsteinPoly& c) {
  return dot(a, cross(b, c));
}

// ---------------------------------------------------------------------------------------------------------------
// BernsteinPatch

BernsteinPatch::BernsteinPatch(int degreeU, int degreeV, Matrix coefficients)
    : du_(degreeU), dv_(degreeV), c_(std::move(coefficients)) {
  assert(c_.rows() == (du_ + 1) * (dv_ + 1));
}

BernsteinPatch BernsteinPatch::zero(int degreeU, int degreeV, int dim) {
  return BernsteinPatch(degreeU, degreeV, Matrix::Zero((degreeU + 1) * (degreeV + 1), dim));
}

VecX BernsteinPatch::operator()(double u, double v) const { return isoU(u)(v); }

BernsteinPoly BernsteinPatch::isoU(double u) const {
  const VecX row = deCasteljau(uRows(*this), u);
  return BernsteinPoly(Matrix(Eigen::Map<const Matrix>(row.data(), dv_ + 1, dim())));
}

BernsteinPoly BernsteinPatch::isoV(double v) const { return swapped().isoU(v); }

BernsteinPoly BernsteinPatch::composed(const BernsteinPoly& u, const BernsteinPoly& v) const {
  assert(u.dim() == 1 && v.dim() == 1);
  // Each u-row (a curve in v) composed with v(t), then de Casteljau in u with polynomial arithmetic.
  const BernsteinPoly oneMinusU = BernsteinPoly::constant(1.0, u.degree()) - u;
  {
    // All u-rows at once, side by side as columns (wide(j, i d + c) = row i's coefficient j, column c): lerpLevels
    // treats every column alike, so each row's composition has the bits of BernsteinPoly::composed(v).
    const Eigen::Index d = dim();
    Matrix wide(dv_ + 1, static_cast<Eigen::Index>(du_ + 1) * d);
    for (int i = 0; i <= du_; ++i)
      wide.middleCols(static_cast<Eigen::Index>(i) * d, d) =
          c_.middleRows(static_cast<Eigen::Index>(i) * (dv_ + 1), dv_ + 1);
    const BernsteinPoly oneMinusV = BernsteinPoly::constant(1.0, v.degree()) - v;
    if (std::optional<Matrix> cv = lerpLevels(wide, dv_, 0, oneMinusV.coeffs(), v.coeffs())) {
      const Eigen::Index m0 = cv->rows() - 1;
      Matrix rows((du_ + 1) * (m0 + 1), d);
      for (int i = 0; i <= du_; ++i)
        rows.middleRows(static_cast<Eigen::Index>(i) * (m0 + 1), m0 + 1) = cv->middleCols(static_cast<Eigen::Index>(i) * d, d);
      if (std::optional<Matrix> c = lerpLevels(rows, du_, static_cast<int>(m0), oneMinusU.coeffs(), u.coeffs()))
        return BernsteinPoly(std::move(*c));
    }
  }
  std::vector<BernsteinPoly> b;
  b.reserve(static_cast<size_t>(du_ + 1));
  for (int i = 0; i <= du_; ++i)
    b.push_back(BernsteinPoly(Matrix(c_.middleRows(static_cast<Eigen::Index>(i) * (dv_ + 1), dv_ + 1))).composed(v));
  {
    const int m0 = b.front().degree();
    Matrix rows(static_cast<Eigen::Index>(du_ + 1) * (m0 + 1), dim());
    for (int i = 0; i <= du_; ++i) rows.middleRows(static_cast<Eigen::Index>(i) * (m0 + 1), m0 + 1) = b[static_cast<size_t>(i)].coeffs();
    if (std::optional<Matrix> c = lerpLevels(rows, du_, m0, oneMinusU.coeffs(), u.coeffs()))
      return BernsteinPoly(std::move(*c));
  }
  for (int r = 1; r <= du_; ++r)
    for (int i = 0; i <= du_ - r; ++i)
      b[static_cast<size_t>(i)] =
          product(oneMinusU, b[static_cast<size_t>(i)]) + product(u, b[static_cast<size_t>(i + 1)]);
  return b.front();
}

BernsteinPoly BernsteinPatch::composed(const BernsteinPoly& u, const BernsteinPoly& v, const BernsteinPoly& w) const {
  assert(u.dim() == 1 && v.dim() == 1 && w.dim() == 1);
  // De Casteljau with homogeneous parameters: (1 - s) a + s b for s = x / w, times w, is (w - x) a + x b.
  auto reduce = [&w](std::vector<BernsteinPoly> b, const BernsteinPoly& x) {
    const BernsteinPoly wMinusX = w - x;
    {
      const int m0 = b.front().degree();
      const Eigen::Index d = b.front().coeffs().cols();
      Matrix rows(static_cast<Eigen::Index>(b.size()) * (m0 + 1), d);
      for (size_t i = 0; i < b.size(); ++i)
        rows.middleRows(static_cast<Eigen::Index>(i) * (m0 + 1), m0 + 1) = b[i].coeffs();
      if (std::optional<Matrix> c =
              lerpLevels(rows, static_cast<int>(b.size()) - 1, m0, wMinusX.coeffs(), x.coeffs()))
        return BernsteinPoly(std::move(*c));
    }
    for (size_t r = 1; r < b.size(); ++r)
      for (size_t i = 0; i + r < b.size(); ++i) b[i] = product(wMinusX, b[i]) + product(x, b[i + 1]);
    return b.front();
  };
  std::vector<BernsteinPoly> rows;
  rows.reserve(static_cast<size_t>(du_ + 1));
  for (int i = 0; i <= du_; ++i) {
    std::vector<BernsteinPoly> b;
    for (int j = 0; j <= dv_; ++j) b.emplace_back(Matrix(c_.row(static_cast<Eigen::Index>(i) * (dv_ + 1) + j)));
    rows.push_back(reduce(std::move(b), v));
  }
  return reduce(std::move(rows), u);
}

BernsteinPatch BernsteinPatch::swapped() const {
  Matrix c(c_.rows(), c_.cols());
  for (int i = 0; i <= du_; ++i)
    for (int j = 0; j <= dv_; ++j) c.row(j * (du_ + 1) + i) = c_.row(i * (dv_ + 1) + j);
  return BernsteinPatch(dv_, du_, std::move(c));
}

BernsteinPatch BernsteinPatch::derivative(int ku, int kv) const {
  BernsteinPatch p = fromURows(derivativeRows(uRows(*this), ku), dv_, dim());
  if (kv == 0) return p;
  const BernsteinPatch s = p.swapped();
  return fromURows(derivativeRows(uRows(s), kv), s.degreeV(), dim()).swapped();
}

BernsteinPatch BernsteinPatch::elevated(int byU, int byV) const {
  BernsteinPatch p = fromURows(elevateRows(uRows(*this), byU), dv_, dim());
  if (byV == 0) return p;
  const BernsteinPatch s = p.swapped();
  return fromURows(elevateRows(uRows(s), byV), s.degreeV(), dim()).swapped();
}

BernsteinPatch BernsteinPatch::elevatedTo(int degreeU, int degreeV) const {
  assert(degreeU >= du_ && degreeV >= dv_);
  return elevated(degreeU - du_, degreeV - dv_);
}

BernsteinPatch BernsteinPatch::restricted(double u0, double u1, double v0, double v1) const {
  const BernsteinPatch p = fromURows(restrictRows(uRows(*this), u0, u1), dv_, dim());
  const BernsteinPatch s = p.swapped();
  return fromURows(restrictRows(uRows(s), v0, v1), s.degreeV(), dim()).swapped();
}

BernsteinPatch BernsteinPatch::reversedU() const {
  return fromURows(Matrix(uRows(*this).colwise().reverse()), dv_, dim());
}

BernsteinPatch BernsteinPatch::reversedV() const { return swapped().reversedU().swapped(); }

VecX BernsteinPatch::minCoeff() const { return c_.colwise().minCoeff().transpose(); }
VecX BernsteinPatch::maxCoeff() const { return c_.colwise().maxCoeff().transpose(); }
double BernsteinPatch::maxAbsCoeff() const { return c_.size() ? c_.cwiseAbs().maxCoeff() : 0.0; }

namespace {
// Tensor-product weighted product of two patches; combine(a_row, b_row) -> out row contribution.
template <class Combine>
BernsteinPatch patchProduct(const BernsteinPatch& a, const BernsteinPatch& b, int outDim, Combine combine) {
  const int n1 = a.degreeU(), m1 = a.degreeV(), n2 = b.degreeU(), m2 = b.degreeV();
  BernsteinPatch out = BernsteinPatch::zero(n1 + n2, m1 + m2, outDim);
  for (int i1 = 0; i1 <= n1; ++i1)
    for (int i2 = 0; i2 <= n2; ++i2) {
      const double fu = binom(n1, i1) * binom(n2, i2) / binom(n1 + n2, i1 + i2);
      for (int j1 = 0; j1 <= m1; ++j1)
        for (int j2 = 0; j2 <= m2; ++j2) {
          const double f = fu * binom(m1, j1) * binom(m2, j2) / binom(m1 + m2, j1 + j2);
          combine(out.coeff(i1 + i2, j1 + j2), f, a.coeff(i1, j1), b.coeff(i2, j2));
        }
    }
  return out;
}
}  // namespace

BernsteinPatch product(const BernsteinPatch& a, const BernsteinPatch& b) {
  assert(a.dim() == b.dim() || a.dim() == 1 || b.dim() == 1);
  const int dim = std::max(a.dim(), b.dim());
  return patchProduct(a, b, dim, [&](auto out, double f, auto x, auto y) {
    if (x.size() == y.size())
      out.array() += f * x.array() * y.array();
    else if (x.size() == 1)
      out += (f * x(0)) * y;
    else
      out += (f * y(0)) * x;
  });
}

BernsteinPatch dot(const BernsteinPatch& a, const BernsteinPatch& b) {
  assert(a.dim() == b.dim());
  return patchProduct(a, b, 1, [](auto out, double f, auto x, auto y) { out(0) += f * x.dot(y); });
}

BernsteinPatch cross(const BernsteinPatch& a, const BernsteinPatch& b) {
  assert(a.dim() == 3 && b.dim() == 3);
  return patchProduct(a, b, 3, [](auto out, double f, auto x, auto y) {
    out(0) += f * (x(1) * y(2) - x(2) * y(1));
    out(1) += f * (x(2) * y(0) - x(0) * y(2));
    out(2) += f * (x(0) * y(1) - x(1) * y(0));
  });
}

std::pair<BernsteinPatch, BernsteinPatch> partialNumerators(const BernsteinPatch& h, bool rational) {
  const BernsteinPatch a(h.degreeU(), h.degreeV(), h.coeffs().leftCols(3));
  if (!rational) return {a.derivative(1, 0), a.derivative(0, 1)};
  const BernsteinPatch w(h.degreeU(), h.degreeV(), h.coeffs().middleCols(3, 1));
  BernsteinPatch su = product(a.derivative(1, 0), w), sv = product(a.derivative(0, 1), w);
  su.coeffs() -= product(a, w.derivative(1, 0)).coeffs();
  sv.coeffs() -= product(a, w.derivative(0, 1)).coeffs();
  return {std::move(su), std::move(sv)};
}

}  // namespace seam
