#pragma once
// `tega export`: one frame of a trained avatar as world-space Gaussians in
// 3DGS's layout (gaussian_ply.h) or in SPZ (gaussian_spz.h), so that standard
// splat viewers show what render_view() renders.
//
// Two things of TeGA have no place in a 3DGS file and are baked:
//  - the covariance J Σ_uvd Jᵀ is decomposed into scale and rotation
//    (eigen-decomposition, rotation with det +1);
//  - the dynamic shading S > 0 multiplies the SH colour. Since
//    S·max(SH(h) + 0.5, 0) = max(SH(h') + 0.5, 0) with
//    h'_0 = ((C0 h_0 + 0.5) S - 0.5) / C0 and h'_k = S h_k (k > 0),
//    the baked coefficients reproduce the shaded colour from every view.
// SH coefficients above the avatar's degree are written as zeros, so a
// degree-3 viewer sees the degree the avatar was trained with.

#include <ATen/ATen.h>

#include <filesystem>
#include <string>

#include "tega/tools/gaussian_ply.h"
#include "tega/trainer/avatar_model.h"

namespace tega::tools {

// The posed Gaussians of one frame (the camera does not matter: neither the
// deformation nor the shading depend on it).
GaussianCloud export_frame(trainer::AvatarModel& model, const trainer::FrameInput& frame,
                           const trainer::Phase& phase);

// Packed covariances [N,6] -> log standard deviations [N,3] and unit
// quaternions [N,4] (w, x, y, z) with R diag(exp(2 log_scale)) Rᵀ = Σ.
// Eigenvalues below `min_variance` are raised to it (a flat Gaussian has no log scale).
struct ScaleRotation {
  at::Tensor log_scale, rotation;
};
ScaleRotation decompose_covariances(const at::Tensor& covariances, double min_variance = 1e-24);

enum class ExportFormat { ply, spz };

// The format `requested` names ("ply" or "spz"); where it is empty, the one
// `out`'s extension names, else PLY. Throws tega::Error when the two disagree.
ExportFormat export_format(const std::string& requested, const std::filesystem::path& out);
std::string file_extension(ExportFormat format);  // ".ply", ".spz"

// write_gaussian_ply or write_gaussian_spz; only SPZ records `antialiased`.
void write_gaussians(const GaussianCloud& cloud, const std::filesystem::path& file, ExportFormat format,
                     bool antialiased);

}  // namespace tega::tools
