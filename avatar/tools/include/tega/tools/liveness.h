#pragma once
// `tega inspect`: is each part of a trained avatar alive, and does it do what
// the paper says it does (TeGA §3.4-3.8; docs/render-eval-export.md#liveness)?
//
//   deformation field (§3.4)  how far it moves the Gaussians in every frame
//                             (the means with and without it), and whether
//                             that follows the expression: Pearson r across
//                             frames against the tracked mesh's mean distance
//                             from the neutral template, head space
//   dynamic shading (§3.5)    the range of the multiplier S over Gaussians and
//                             frames, how much one Gaussian's S varies across
//                             frames, and r of mean |S - 1| against the expression
//   free UVD binding (§3.3)   the fraction of Gaussians no longer on the
//                             triangle they were created on
//   the mesh's error (§3.4)   with a virtual-studio capture's ground truth:
//                             how far the dataset's meshes put each Gaussian
//                             from where the true meshes would, and how much
//                             of that the deformation field undoes: all of it,
//                             and its frame-to-frame part, which the canonical
//                             Gaussians cannot absorb
//   gradients                 the mean L2 norm of the photometric loss's
//                             gradient (L1 + D-SSIM, the run's weights) that
//                             each part receives, over training views
//
// A part the run has switched off is reported as off, not as zero.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tega/core/dataset.h"
#include "tega/trainer/trained_avatar.h"

namespace tega::tools {

struct LivenessOptions {
  int gradient_views = 8;  // training views (spread over frames and cameras) for the gradients
  // A `tega synth` capture (with truth_apart, its CAPTURE.truth/) whose
  // ground_truth/ holds the true meshes of the dataset's frames; empty: the
  // mesh's error is not scored.
  std::filesystem::path truth;
};

struct FrameLiveness {
  std::string frame;
  double expression_mm = 0;        // mean distance of the tracked mesh from the template, head space
  double deformation_mean_mm = 0;  // |Δμ| over the Gaussians the field moves
  double deformation_p95_mm = 0;
  double shading_p01 = 1, shading_p50 = 1, shading_p99 = 1;
  // With a truth: RMS over the Gaussians of their distance from where the
  // frame's true mesh puts them, placed by the dataset's mesh alone and with
  // the deformation field (absent where the field is off).
  std::optional<double> mesh_error_mm, corrected_error_mm;
};

struct PartGradient {
  std::string part;  // gaussians.<parameter>, network.encoder, network.deformation, network.shading
  double mean_norm = 0;
};

struct Liveness {
  int64_t gaussians = 0;
  int64_t iteration = 0;
  bool deformation = false, shading = false;
  std::vector<FrameLiveness> frames;      // every dataset frame
  double deformation_expression_r = 0;    // NaN where undefined (constant series)
  double deformation_frame_std_mm = 0;    // mean over Gaussians of Δμ's std over frames (head space)
  double shading_frame_std = 0;           // mean over Gaussians of S's std over frames
  double shading_expression_r = 0;
  std::optional<double> off_birth_triangle;  // fraction; absent when the run does not track it
  // With a truth and the field on: 1 - corrected / mesh error (RMS over the
  // split's frames and Gaussians) on training and held-out frames, the share
  // of the meshes' error the field undoes (1 all, 0 none, < 0 it adds error).
  std::optional<double> error_undone_train, error_undone_test;
  // The same for the error's frame-to-frame part: each Gaussian's error
  // vector (head space) less its mean over the split's frames. What is common
  // to a split's frames the canonical Gaussians can absorb; this part only the
  // field can undo. Its RMS (mm, without the field) and the share undone;
  // absent without a truth or below two frames in the split, and the share
  // also with the field off.
  std::optional<double> varying_error_mm_train, varying_error_mm_test;
  std::optional<double> varying_error_undone_train, varying_error_undone_test;
  std::vector<PartGradient> gradients;
};

Liveness inspect_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset, const LivenessOptions& options);

nlohmann::json liveness_json(const Liveness& liveness);
std::string liveness_markdown(const Liveness& liveness, const std::string& name);

}  // namespace tega::tools
