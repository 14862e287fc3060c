// fused_uvd_to_world: checks, the autograd Function, the CPU loops and the
// dispatch to the CUDA kernels.

#include "fused_uvd_map.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include "fused_uvd_map_glue.h"
#include "tega/avatar/device_dispatch.h"

namespace tega::uvd {
namespace fused_uvd_map {

std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                                              const SurfaceTensors& surface) {
  const int64_t n = uvd.size(0);
  at::Tensor xyz = at::empty({n, 3}, uvd.options()), jacobian = at::empty({n, 3, 3}, uvd.options());
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "uvd_to_world", [&] {
    const Surface<scalar_t> s = pointers<scalar_t>(surface);
    const int64_t* t = triangle.data_ptr<int64_t>();
    const scalar_t* q = uv.data_ptr<scalar_t>();
    const scalar_t* p = uvd.data_ptr<scalar_t>();
    scalar_t* x = xyz.data_ptr<scalar_t>();
    scalar_t* j = jacobian.data_ptr<scalar_t>();
    at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) forward_element(s, t[i], q + 2 * i, p[3 * i + 2], x + 3 * i, j + 9 * i);
    });
  });
  return {xyz, jacobian};
}

at::Tensor backward_cpu(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                        const SurfaceTensors& surface, const at::Tensor& grad_xyz, const at::Tensor& grad_jacobian) {
  at::Tensor grad_uvd = at::empty_like(uvd);
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "uvd_to_world_backward", [&] {
    const Surface<scalar_t> s = pointers<scalar_t>(surface);
    const int64_t* t = triangle.data_ptr<int64_t>();
    const scalar_t* q = uv.data_ptr<scalar_t>();
    const scalar_t* p = uvd.data_ptr<scalar_t>();
    const scalar_t* gx = grad_xyz.defined() ? grad_xyz.data_ptr<scalar_t>() : nullptr;
    const scalar_t* gj = grad_jacobian.defined() ? grad_jacobian.data_ptr<scalar_t>() : nullptr;
    scalar_t* g = grad_uvd.data_ptr<scalar_t>();
    at::parallel_for(0, uvd.size(0), 1024, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i)
        backward_element(s, t[i], q + 2 * i, p[3 * i + 2], gx ? gx + 3 * i : nullptr, gj ? gj + 9 * i : nullptr,
                         g + 3 * i);
    });
  });
  return grad_uvd;
}

}  // namespace fused_uvd_map

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;
using fused_uvd_map::SurfaceTensors;

class FusedUvdToWorldFunction : public torch::autograd::Function<FusedUvdToWorldFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& uvd, const at::Tensor& uv,
                               const at::Tensor& triangle, const at::Tensor& faces, const at::Tensor& vertices,
                               const at::Tensor& normals, const at::Tensor& corners, const at::Tensor& inverse,
                               const at::Tensor& gradient) {
    ctx->save_for_backward({uvd, uv, triangle, faces, vertices, normals, corners, inverse, gradient});
    ctx->set_materialize_grads(false);  // an unused output's gradient stays undefined, not zeros
    const SurfaceTensors surface{faces, vertices, normals, corners, inverse, gradient};
    std::pair<at::Tensor, at::Tensor> out;
    if (use_cuda_kernels(uvd, "uvd_to_world")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      out = fused_uvd_map::forward_cuda(uvd, uv, triangle, surface);
#endif
    } else {
      out = fused_uvd_map::forward_cpu(uvd, uv, triangle, surface);
    }
    return {out.first, out.second};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list s = ctx->get_saved_variables();
    const SurfaceTensors surface{s[3], s[4], s[5], s[6], s[7], s[8]};
    const at::Tensor grad_xyz = grads[0].defined() ? grads[0].contiguous() : at::Tensor();
    const at::Tensor grad_jacobian = grads[1].defined() ? grads[1].contiguous() : at::Tensor();
    variable_list out(9);
    if (!grad_xyz.defined() && !grad_jacobian.defined()) return out;
    if (use_cuda_kernels(s[0], "uvd_to_world")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      out[0] = fused_uvd_map::backward_cuda(s[0], s[1], s[2], surface, grad_xyz, grad_jacobian);
#endif
    } else {
      out[0] = fused_uvd_map::backward_cpu(s[0], s[1], s[2], surface, grad_xyz, grad_jacobian);
    }
    return out;
  }
};

}  // namespace

std::pair<at::Tensor, at::Tensor> fused_uvd_to_world(const at::Tensor& uvd, const at::Tensor& mapped_uv,
                                                     const at::Tensor& triangle, const PosedMesh& mesh,
                                                     const UvTriangleLookup& lookup) {
  TORCH_CHECK(!mesh.vertices.requires_grad() && !mesh.normals.requires_grad(),
              "uvd_to_world: the fused evaluation gives no gradient to the posed mesh");
  const at::ScalarType dtype = uvd.scalar_type();
  const variable_list out = FusedUvdToWorldFunction::apply(
      uvd.contiguous(), mapped_uv.contiguous(), triangle.contiguous(),
      lookup.faces().contiguous(), mesh.vertices.contiguous(), mesh.normals.contiguous(),
      lookup.uv_corners(dtype).contiguous(), lookup.barycentric_inverse(dtype).contiguous(),
      lookup.barycentric_gradient(dtype).contiguous());
  return {out[0], out[1]};
}

}  // namespace tega::uvd
