// bench/track: time per frame of template tracking for ICT-FaceKit's topology
// (26,719 vertices) on a virtual-studio capture it renders (13 cameras) or
// one given: the identity fit once, then per frame the image terms (optical
// flow, landmarks), pose and expression, and per-vertex corrections. Scans
// are the capture's MVS meshes (--meshes) or, by default, its true meshes.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "tega/core/error.h"
#include "tega/core/mesh.h"
#include "tega/core/options.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/thread_pool.h"
#include "tega/landmarks/landmarks.h"
#include "tega/scoring/tracking_scores.h"
#include "tega/synth/virtual_studio.h"
#include "tega/tracking/head_model.h"
#include "tega/tracking/photos.h"
#include "tega/tracking/tracker.h"

namespace fs = std::filesystem;
using namespace tega;

namespace {

Mesh scan_of(const fs::path& capture, const fs::path& meshes, const Mesh& fine_topology, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d", frame);
  if (!meshes.empty()) return read_mesh(meshes / "expressions" / (std::string(name) + ".ply"));
  Mesh scan = fine_topology;
  scan.positions = read_vertices_bin(capture / "ground_truth" / "expressions" / "fine" / (std::string(name) + ".bin"),
                                     fine_topology.num_vertices());
  return scan;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Time per frame of tega's template tracking (ICT-FaceKit topology)."};
  std::string model_dir = "../shared/data/ict-facekit", capture_dir, meshes_dir, landmarks;
  int frames = 0, width = 512, height = 384, threads = 2;
  bool no_flow = false;
  app.add_option("--model", model_dir, "The ICT-FaceKit directory.");
  app.add_option("--capture", capture_dir, "A virtual-studio capture to track (default: render one).");
  std::vector<std::string> overrides;
  app.add_option("--set", overrides, "Override a tracking option, e.g. --set eyelids.enabled=false (repeatable).");
  app.add_option("--meshes", meshes_dir, "Its MVS meshes (MESHES/expressions/<frame>.ply; default: the true meshes).");
  app.add_option("--frames", frames, "Frames of the take to render and track (default: bench/track_studio.yaml's 10).");
  app.add_option("--width", width, "Image width of the rendered capture.");
  app.add_option("--height", height, "Image height of the rendered capture.");
  app.add_option("--threads", threads, "Worker threads (the target machine has 2 cores).");
  app.add_option("--landmarks", landmarks, "A dlib 68-point shape predictor for the landmark term.");
  app.add_flag("--no-flow", no_flow, "Track without the optical-flow term.");
  std::vector<int> ignored_landmarks;
  app.add_option("--ignored-landmarks", ignored_landmarks,
                 "0-based 68-point landmarks the per-frame fit leaves out (e.g. the eyelids, 36 ... 47).");
  bool detector_boxes = false;
  app.add_flag("--detector-boxes", detector_boxes,
               "Boxes from dlib's face detector (for dlib's own predictor) instead of around the posed model.");
  CLI11_PARSE(app, argc, argv);

  tracking::Options options;
  options.threads = threads;
  options.landmarks.model = landmarks;
  options.landmarks.detector_boxes = detector_boxes;
  options.landmarks.ignored_points = ignored_landmarks;
  options.flow.enabled = !no_flow;
  try {
    for (const auto& kv : overrides) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw Error("--set " + kv + ": expected key=value");
      set_option(options, kv.substr(0, eq), kv.substr(eq + 1));
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  fs::path capture = capture_dir;
  if (capture.empty()) {
    capture = fs::temp_directory_path() / "tega-track-bench";
    synth::Options studio;
    load_options(studio, TEGA_BENCH_TRACK_STUDIO);
    studio.studio.width = width;
    studio.studio.height = height;
    if (frames > 0) studio.frames = frames;
    studio.head = model_dir;
    studio.threads = threads;
    std::printf("rendering %s (%d frames, 13 cameras, %dx%d)\n", capture.c_str(), studio.frames, width, height);
    synth::render_virtual_studio(studio, capture, true);
  }

  const tracking::HeadModel model = tracking::load_head_model(model_dir, options.model_metres_per_unit);
  const std::unique_ptr<tega::landmarks::LandmarkDetector> detector =
      landmarks.empty() ? nullptr : std::make_unique<tega::landmarks::LandmarkDetector>(landmarks);
  const Rig rig = read_rig_json(capture / "rig.json");
  const TakeInfo take = read_take(capture / "takes" / "expressions");
  const Mesh fine_topology = meshes_dir.empty() ? read_obj(capture / "ground_truth" / "head" / "fine_topology.obj") : Mesh{};
  // As tega track reads them: downsampled within options.photo_max_side.
  std::vector<Camera> cameras;
  for (const auto& name : take.cameras) cameras.push_back(rig.camera(name));
  const int photo_factor = tracking::photo_downsample(cameras, options.photo_max_side);
  cameras = tracking::photo_cameras(cameras, photo_factor);
  ThreadPool pool(threads);
  const auto photos = [&](int frame) { return tracking::frame_photos(take, frame, photo_factor, pool); };

  const Mesh first = scan_of(capture, meshes_dir, fine_topology, 0);
  auto start = std::chrono::steady_clock::now();
  const tracking::SubjectIdentity subject =
      tracking::fit_identity(model, {{&first, photos(0)}}, cameras, options, detector.get());
  std::printf("identity fit: %.2f s (once per subject)\n", seconds_since(start));

  tracking::TakeTracker tracker(model, subject, cameras, options, detector.get());
  std::printf("%-6s %10s %12s %12s %12s %10s %12s %12s   %s\n", "frame", "scan faces", "image terms", "pose+expr",
              "corrections", "total (s)", "flow points", "flow rms px", "blink (eye covered in the photos)");
  double total = 0;
  int counted = 0;
  std::vector<scoring::ScoredFrame> scored;
  for (int frame = 0; frame < take.frames; ++frame) {
    const Mesh scan = scan_of(capture, meshes_dir, fine_topology, frame);
    const tracking::FrameObservation observation{&scan, photos(frame)};
    start = std::chrono::steady_clock::now();
    const tracking::FrameFit fit = tracker.track(observation);
    const double seconds = seconds_since(start);
    tracker.accept(fit, observation);
    scoring::ScoredFrame t{frame, fit.vertices, fit.state.head_to_world.R, {}};
    for (size_t k = 0; k < fit.state.expression.size(); ++k)
      t.expression[model.shapes.expression_names[k]] = fit.state.expression[k];
    scored.push_back(std::move(t));
    std::printf("%-6d %10d %12.2f %12.2f %12.2f %10.2f %12d %12.2f ", frame, scan.num_faces(), fit.timings.image_terms_s,
                fit.timings.coefficients_s, fit.timings.corrections_s, seconds, fit.residuals.flow_count,
                fit.residuals.flow_rms_px);
    for (const auto& name : options.eyelids.shapes) {
      std::printf("  %s %.2f", name.c_str(), scored.back().expression.at(name));
      if (fit.residuals.eyelids_covered.count(name)) std::printf(" (%.2f)", fit.residuals.eyelids_covered.at(name));
    }
    std::printf("%s\n", fit.fitted_afresh ? "  fitted afresh" : "");
    if (frame > 0) total += seconds, ++counted;  // frame 0 also finds the first pose
  }
  if (counted) std::printf("mean over frames 1..%d: %.2f s per frame (%d threads)\n", take.frames - 1, total / counted, threads);
  if (fs::exists(capture / "ground_truth")) {
    const scoring::TakeTruth truth(capture, "expressions");
    const scoring::TrackScores s = truth.score(scored, &subject.neutral);
    std::printf("against the truth: vertex error median %.3f mm, p95 %.3f mm; rotation error median %.3f deg, "
                "max %.3f deg (the fitted subject is turned %.3f deg from the true one; without that taken out the "
                "poses are %.3f deg off)\n",
                1000 * s.vertex_median_m, 1000 * s.vertex_p95_m, s.rotation_median_deg, s.rotation_max_deg,
                s.subject_rotation_deg, s.pose_rotation_median_deg);
    for (const auto& [name, r] : s.correlation) std::printf("  %-16s r = %.3f\n", name.c_str(), r);
    for (const scoring::ScoredFrame& frame : scored) {  // which frame a bad median or maximum comes from
      const scoring::TrackScores f = truth.score({frame}, &subject.neutral);
      std::printf("  frame %d: vertex error median %.3f mm, p95 %.3f mm; rotation error %.3f deg\n", frame.frame,
                  1000 * f.vertex_median_m, 1000 * f.vertex_p95_m, f.rotation_median_deg);
    }
  }
  return 0;
}
