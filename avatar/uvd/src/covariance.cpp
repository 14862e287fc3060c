#include "tega/uvd/covariance.h"

namespace tega::uvd {

at::Tensor rotation_from_quaternion(const at::Tensor& quaternion) {
  TORCH_CHECK(quaternion.dim() == 2 && quaternion.size(1) == 4, "quaternion must be [N,4]");
  const auto q = quaternion / quaternion.norm(2, 1, /*keepdim=*/true);
  const auto w = q.select(1, 0), x = q.select(1, 1), y = q.select(1, 2), z = q.select(1, 3);
  const auto rows = at::stack({1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                               2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                               2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
                              1);
  return rows.view({-1, 3, 3});
}

at::Tensor covariance_from_scale_rotation(const at::Tensor& scale, const at::Tensor& quaternion) {
  const auto m = rotation_from_quaternion(quaternion) * scale.unsqueeze(1);  // R diag(s)
  return batched_matmul(m, m.transpose(1, 2));
}

at::Tensor world_covariance(const at::Tensor& jacobian, const at::Tensor& covariance_uvd) {
  TORCH_CHECK(jacobian.dim() == 3 && jacobian.size(1) == 3 && jacobian.size(2) == 3, "jacobian must be [N,3,3]");
  const auto product = batched_matmul(batched_matmul(jacobian, covariance_uvd), jacobian.transpose(1, 2));
  // Rounding leaves the product slightly asymmetric; the rasterizer assumes symmetry.
  return 0.5 * (product + product.transpose(1, 2));
}

at::Tensor world_covariance(const at::Tensor& jacobian, const at::Tensor& scale, const at::Tensor& quaternion) {
  const auto m = batched_matmul(jacobian, rotation_from_quaternion(quaternion) * scale.unsqueeze(1));  // J R diag(s)
  return batched_matmul(m, m.transpose(1, 2));
}

at::Tensor pack_symmetric(const at::Tensor& matrix) {
  return at::stack({matrix.select(2, 0).select(1, 0), matrix.select(2, 1).select(1, 0),
                    matrix.select(2, 2).select(1, 0), matrix.select(2, 1).select(1, 1),
                    matrix.select(2, 2).select(1, 1), matrix.select(2, 2).select(1, 2)},
                   1);
}

at::Tensor unpack_symmetric(const at::Tensor& packed) {
  TORCH_CHECK(packed.dim() == 2 && packed.size(1) == 6, "packed covariance must be [N,6]");
  const auto c = [&](int k) { return packed.select(1, k); };
  return at::stack({c(0), c(1), c(2), c(1), c(3), c(4), c(2), c(4), c(5)}, 1).view({-1, 3, 3});
}

at::Tensor batched_matmul(const at::Tensor& a, const at::Tensor& b) {
  TORCH_CHECK(a.dim() == 3 && b.dim() == 3 && a.size(2) == b.size(1), "batched_matmul: shapes ", a.sizes(), " and ",
              b.sizes(), " do not multiply");
  return (a.unsqueeze(3) * b.unsqueeze(1)).sum(2);
}

}  // namespace tega::uvd
