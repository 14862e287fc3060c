#pragma once
// Tracking a capture's takes (`tega track`, docs/tracking.md): the subject's
// identity (fitted once, or reused from an earlier session), then every frame
// of each take in order against its multi-view stereo mesh, written as
//   TRACKED/identity.json + identity_neutral.obj   the subject
//   TRACKED/<take>/<frame:06d>.bin                 tracked mesh, world space, template topology
//   TRACKED/<take>/<frame:06d>.json                pose, expression, residuals, status
//   TRACKED/<take>/report/                         residual plots and overlays (PNG)
//   TRACKED/<take>/track.json                      the take's summary, written last
// Takes are independent once the identity is known; a rerun with the same
// options resumes each take after its last written frame. A take may also be
// tracked in frame ranges by processes at once (a split `track` shard): the
// first to need the identity fits it while the others wait for it (a lock
// file), each range's first frame is fitted afresh, and the range that
// completes the take writes its summary and report.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/tracking/head_model.h"
#include "tega/tracking/options.h"
#include "tega/tracking/tracker.h"

namespace tega::tracking {

struct TrackRequest {
  std::filesystem::path capture;   // CAPTURE/: capture.json, rig.json, takes/
  std::vector<std::string> takes;  // empty: every performance take
  std::filesystem::path meshes;    // MESHES/<take>/<frame:06d>.ply (tega mvs)
  std::filesystem::path out;       // TRACKED/
  std::filesystem::path rig;       // empty: the capture's rig.json
  int first_frame = 0, end_frame = -1;  // frames [first, end) of each take; end -1: to the take's end
};

struct TrackSummary {
  int takes = 0;
  int frames_tracked = 0;
  int frames_failed = 0;   // fitted but rejected (recorded, no mesh written)
  int frames_skipped = 0;  // no scan
  int frames_kept = 0;     // done by an earlier run
};

// The model and a reused identity come from options.model and options.identity.
TrackSummary track_capture(const TrackRequest& request, const Options& options);

// identity.json: the model it belongs to, the identity coefficients by
// name, and the subject's neutral mesh (identity_neutral.obj beside it,
// head space, with the model's UVs). Atomic.
void write_identity(const SubjectIdentity& subject, const HeadModel& model, const std::filesystem::path& file);
// Throws tega::Error naming the file when it does not fit `model`.
SubjectIdentity read_identity(const std::filesystem::path& file, const HeadModel& model);

}  // namespace tega::tracking
