// identity.json + identity_neutral.obj: a subject fitted once and reused for
// every take and session, in core's tracked layout (tega/core/tracked.h).
#include "tega/core/error.h"
#include "tega/core/tracked.h"
#include "tega/tracking/tracking.h"

namespace tega::tracking {
namespace fs = std::filesystem;

void write_identity(const SubjectIdentity& subject, const HeadModel& model, const fs::path& file) {
  TrackedSubject tracked;
  tracked.model = fs::absolute(model.directory);
  tracked.neutral = model.shapes.neutral;
  tracked.neutral.positions = subject.neutral;
  for (size_t k = 0; k < subject.coefficients.size(); ++k)
    tracked.identity[model.shapes.identity_names[k]] = subject.coefficients[k];
  tracked.open_eyes_covered = subject.open_eyes_covered;
  // What later stages need of the model without loading it.
  tracked.eyeball_vertices = model.eyeball_vertices;
  tracked.landmark_vertices = model.landmark_vertices;
  write_tracked_subject(tracked, file);
}

SubjectIdentity read_identity(const fs::path& file, const HeadModel& model) {
  const TrackedSubject tracked = read_tracked_subject_file(file);
  if (tracked.neutral.num_vertices() != model.num_vertices())
    throw Error(file, "was fitted to a model with " + std::to_string(tracked.neutral.num_vertices()) +
                          " vertices, not " + model.directory.string() + " (" + std::to_string(model.num_vertices()) +
                          ")");
  SubjectIdentity subject;
  for (const auto& name : model.shapes.identity_names) {
    const auto it = tracked.identity.find(name);
    subject.coefficients.push_back(it == tracked.identity.end() ? 0.0 : it->second);
  }
  subject.open_eyes_covered = tracked.open_eyes_covered;
  subject.neutral = tracked.neutral.positions;
  return subject;
}

}  // namespace tega::tracking
