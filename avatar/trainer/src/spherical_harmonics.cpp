#include "tega/trainer/spherical_harmonics.h"

#include <vector>

namespace tega::trainer {

at::Tensor sh_to_rgb(const at::Tensor& sh, const at::Tensor& directions, int degree) {
  // Real SH basis constants (the ones 3DGS uses).
  constexpr double c0 = 0.28209479177387814;
  constexpr double c1 = 0.4886025119029199;
  constexpr double c2[] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                           0.5462742152960396};
  constexpr double c3[] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                           -0.4570457994644658, 1.445305721320277, -0.5900435899266435};

  const at::Tensor d = directions / directions.norm(2, 1, true).clamp_min(1e-12);
  const at::Tensor x = d.select(1, 0).unsqueeze(1), y = d.select(1, 1).unsqueeze(1), z = d.select(1, 2).unsqueeze(1);
  const auto h = [&](int k) { return sh.select(1, k); };  // [N, 3]

  at::Tensor rgb = c0 * h(0);
  if (degree >= 1) rgb = rgb - c1 * y * h(1) + c1 * z * h(2) - c1 * x * h(3);
  if (degree >= 2) {
    const at::Tensor xx = x * x, yy = y * y, zz = z * z, xy = x * y, yz = y * z, xz = x * z;
    rgb = rgb + c2[0] * xy * h(4) + c2[1] * yz * h(5) + c2[2] * (2.0 * zz - xx - yy) * h(6) + c2[3] * xz * h(7) +
          c2[4] * (xx - yy) * h(8);
    if (degree >= 3) {
      rgb = rgb + c3[0] * y * (3.0 * xx - yy) * h(9) + c3[1] * xy * z * h(10) +
            c3[2] * y * (4.0 * zz - xx - yy) * h(11) + c3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * h(12) +
            c3[4] * x * (4.0 * zz - xx - yy) * h(13) + c3[5] * z * (xx - yy) * h(14) +
            c3[6] * x * (xx - 3.0 * yy) * h(15);
    }
  }
  return (rgb + 0.5).clamp_min(0.0);
}

}  // namespace tega::trainer
