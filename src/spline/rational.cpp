// Quotient rules that turn derivatives of a homogeneous (w P, w) curve or surface into derivatives of P.
#include "seam/core/bernstein.h"
#include "spline/spline_internal.h"

namespace seam::detail {

Matrix curveQuotientRule(const Matrix& H) {
  const auto d = H.cols() - 1;
  const auto order = H.rows() - 1;
  Matrix C(order + 1, d);
  for (Eigen::Index k = 0; k <= order; ++k) {
    Eigen::RowVectorXd v = H.row(k).head(d);
    for (Eigen::Index i = 1; i <= k; ++i)
      v -= binomial(static_cast<int>(k), static_cast<int>(i)) * H(i, d) * C.row(k - i);
    C.row(k) = v / H(0, d);
  }
  return C;
}

std::vector<std::vector<VecX>> surfaceQuotientRule(const std::vector<std::vector<VecX>>& H) {
  const int order = static_cast<int>(H.size()) - 1;
  const auto d = H[0][0].size() - 1;
  auto at = [](auto& m, int k, int l) -> auto& { return m[static_cast<size_t>(k)][static_cast<size_t>(l)]; };
  auto w = [&](int k, int l) { return at(H, k, l)[d]; };
  std::vector<std::vector<VecX>> S(static_cast<size_t>(order + 1));
  for (int k = 0; k <= order; ++k) {
    S[static_cast<size_t>(k)].resize(static_cast<size_t>(order - k + 1));
    for (int l = 0; l <= order - k; ++l) {
      VecX v = at(H, k, l).head(d);
      for (int j = 1; j <= l; ++j) v -= binomial(l, j) * w(0, j) * at(S, k, l - j);
      for (int i = 1; i <= k; ++i) {
        v -= binomial(k, i) * w(i, 0) * at(S, k - i, l);
        VecX v2 = VecX::Zero(d);
        for (int j = 1; j <= l; ++j) v2 += binomial(l, j) * w(i, j) * at(S, k - i, l - j);
        v -= binomial(k, i) * v2;
      }
      at(S, k, l) = v / w(0, 0);
    }
  }
  return S;
}

}  // namespace seam::detail
