#include "tega/trainer/spherical_harmonics.h"

#include <vector>

namespace tega::trainer {
namespace {

// The real SH basis at the normalised directions: (degree+1)² tensors [N].
std::vector<at::Tensor> sh_basis(const at::Tensor& directions, int degree) {
  // Real SH basis constants (the ones 3DGS uses).
  constexpr double c0 = 0.28209479177387814;
  constexpr double c1 = 0.4886025119029199;
  constexpr double c2[] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                           0.5462742152960396};
  constexpr double c3[] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                           -0.4570457994644658, 1.445305721320277, -0.5900435899266435};

  const at::Tensor d = directions / directions.norm(2, 1, true).clamp_min(1e-12);
  const at::Tensor x = d.select(1, 0), y = d.select(1, 1), z = d.select(1, 2);
  std::vector<at::Tensor> basis{at::full_like(x, c0)};
  if (degree >= 1) basis.insert(basis.end(), {-c1 * y, c1 * z, -c1 * x});
  if (degree >= 2) {
    const at::Tensor xx = x * x, yy = y * y, zz = z * z, xy = x * y, yz = y * z, xz = x * z;
    basis.insert(basis.end(), {c2[0] * xy, c2[1] * yz, c2[2] * (2.0 * zz - xx - yy), c2[3] * xz, c2[4] * (xx - yy)});
    if (degree >= 3) {
      basis.insert(basis.end(), {c3[0] * y * (3.0 * xx - yy), c3[1] * xy * z, c3[2] * y * (4.0 * zz - xx - yy),
                                 c3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy), c3[4] * x * (4.0 * zz - xx - yy),
                                 c3[5] * z * (xx - yy), c3[6] * x * (xx - 3.0 * yy)});
    }
  }
  return basis;
}

// Σ_k basis_k coefficients_k as one product: [N,K]·[N,K,3] -> [N,3]. (A sum
// of K [N,3] terms costs K passes over memory forward and more backward.)
at::Tensor weighted_sum(const std::vector<at::Tensor>& basis, const at::Tensor& coefficients) {
  const int64_t k = static_cast<int64_t>(basis.size());
  TORCH_CHECK(coefficients.dim() == 3 && coefficients.size(1) >= k && coefficients.size(2) == 3,
              "SH coefficients must be [N,>=", k, ",3], got ", coefficients.sizes());
  return (at::stack(basis, 1).unsqueeze(2) * coefficients.narrow(1, 0, k)).sum(1);
}

}  // namespace

at::Tensor sh_to_rgb(const at::Tensor& sh, const at::Tensor& directions, int degree) {
  return (weighted_sum(sh_basis(directions, degree), sh) + 0.5).clamp_min(0.0);
}

at::Tensor sh_to_rgb(const at::Tensor& sh_dc, const at::Tensor& sh_rest, const at::Tensor& directions, int degree) {
  std::vector<at::Tensor> basis = sh_basis(directions, degree);
  at::Tensor rgb = basis.front().unsqueeze(1) * sh_dc.select(1, 0);
  if (basis.size() > 1) rgb = rgb + weighted_sum({basis.begin() + 1, basis.end()}, sh_rest);
  return (rgb + 0.5).clamp_min(0.0);
}

}  // namespace tega::trainer
