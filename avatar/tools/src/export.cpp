#include "tega/tools/export.h"

#include <ATen/Parallel.h>
#include <ATen/core/grad_mode.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "tega/core/error.h"
#include "tega/tools/gaussian_spz.h"
#include "tega/trainer/spherical_harmonics.h"

namespace tega::tools {

ScaleRotation decompose_covariances(const at::Tensor& covariances, double min_variance) {
  // Double precision on the CPU: Eigen's 3x3 solver is exact to rounding and
  // the result is stored as float32 anyway.
  const at::Tensor packed = covariances.detach().to(at::kCPU, at::kDouble).contiguous();
  const int64_t n = packed.size(0);
  at::Tensor log_scale = at::empty({n, 3}, packed.options());
  at::Tensor rotation = at::empty({n, 4}, packed.options());
  const double* in = packed.data_ptr<double>();
  double* scale_out = log_scale.data_ptr<double>();
  double* rot_out = rotation.data_ptr<double>();
  at::parallel_for(0, n, 4096, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const double* s = in + 6 * i;
      Eigen::Matrix3d sigma;
      sigma << s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5];
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(sigma);
      Eigen::Matrix3d r = solver.eigenvectors();
      if (r.determinant() < 0) r.col(2) = -r.col(2);  // a rotation, not a reflection
      for (int k = 0; k < 3; ++k) scale_out[3 * i + k] = 0.5 * std::log(std::max(solver.eigenvalues()[k], min_variance));
      Eigen::Quaterniond q(r);
      q.normalize();
      if (q.w() < 0) q.coeffs() = -q.coeffs();  // one of the two equivalent signs, for stable files
      rot_out[4 * i + 0] = q.w();
      rot_out[4 * i + 1] = q.x();
      rot_out[4 * i + 2] = q.y();
      rot_out[4 * i + 3] = q.z();
    }
  });
  return {log_scale, rotation};
}

GaussianCloud export_frame(trainer::AvatarModel& model, const trainer::FrameInput& frame, const trainer::Phase& phase) {
  at::NoGradGuard no_grad;
  const trainer::PosedGaussians posed = model.pose(frame, phase);
  const trainer::Gaussians& g = model.gaussians;

  // posed.sh holds the degrees the avatar uses, with the shading folded in; the file has all 16 coefficients.
  at::Tensor sh = at::zeros({g.sh_dc.size(0), trainer::sh_coefficients(3), 3}, g.sh_dc.options());
  sh.narrow(1, 0, posed.sh.size(1)).copy_(posed.sh);

  const ScaleRotation shape = decompose_covariances(posed.covariances);
  GaussianCloud cloud;
  cloud.means = posed.means.detach().to(at::kCPU, at::kFloat);
  cloud.sh = sh.to(at::kCPU, at::kFloat);
  cloud.opacity_logit = g.opacity_logit.detach().to(at::kCPU, at::kFloat);
  cloud.log_scale = shape.log_scale.to(at::kFloat);
  cloud.rotation = shape.rotation.to(at::kFloat);
  return cloud;
}

ExportFormat export_format(const std::string& requested, const std::filesystem::path& out) {
  const std::string extension = out.extension().string();
  const bool named_by_extension = extension == ".ply" || extension == ".spz";
  if (requested.empty()) return extension == ".spz" ? ExportFormat::spz : ExportFormat::ply;
  if (requested != "ply" && requested != "spz") throw Error("tega export: --format " + requested + ": use ply or spz");
  if (named_by_extension && extension != "." + requested)
    throw Error(out, "names a " + extension.substr(1) + " file, but --format is " + requested);
  return requested == "spz" ? ExportFormat::spz : ExportFormat::ply;
}

std::string file_extension(ExportFormat format) { return format == ExportFormat::spz ? ".spz" : ".ply"; }

void write_gaussians(const GaussianCloud& cloud, const std::filesystem::path& file, ExportFormat format,
                     bool antialiased) {
  if (format == ExportFormat::spz) write_gaussian_spz(cloud, file, antialiased);
  else write_gaussian_ply(cloud, file);
}

}  // namespace tega::tools
