#pragma once
// Options of the alpha mattes (`tega matte`, docs/matting.md).

#include <string>

namespace tega::matting {

// Where the clean plate says the subject is: the difference of a frame from
// the same camera's image of the empty studio, after matching its exposure.
struct DifferenceOptions {
  double noise_sigma = 0;         // sensor noise, [0, 1] units; 0: measured per image on the far background
  double subject_sigmas = 6;      // a 3 x 3 mean difference above this many of its noise sigmas is subject
  double max_exposure_change = 0.3;  // the frame's gain against the clean plate is clamped to 1 +- this
  double shading_tolerance = 0;   // per-pixel brightness change explained as shading, not subject: 1 +- this
  int open_px = 1;                // subject specks narrower than this are dropped
  int close_px = 2;               // gaps in the subject narrower than this are closed

  template <class V>
  void visit(V& v) {
    v("noise_sigma", noise_sigma,
      "Sensor noise of one pixel (0..1 units); 0: measured on each image's background, far from the subject.");
    v("subject_sigmas", subject_sigmas,
      "A pixel whose 3x3 mean differs from the clean plate by more than this many sigmas of that mean's noise is "
      "subject.");
    v("max_exposure_change", max_exposure_change,
      "Largest exposure drift corrected: the per-channel gain of a frame against its clean plate stays within "
      "1 +- this.");
    v("shading_tolerance", shading_tolerance,
      "A pixel as much as this much brighter or darker than the clean plate, with its colour, is still "
      "background (a shadow cast on the backdrop, a change of daylight); 0 for the studio's fixed light. Dark "
      "hair on a grey backdrop is a darker grey: keep this below its contrast.");
    v("open_px", open_px, "Specks of subject narrower than this many pixels are dropped (a morphological opening).");
    v("close_px", close_px, "Gaps in the subject narrower than this many pixels are closed.");
  }
};

// The tracked mesh's silhouette through the camera's lens: the head for sure,
// but not hair, shoulders or anything else the model lacks.
struct MeshPriorOptions {
  double margin_m = 0.004;        // how far the tracked surface may lie from the true one
  bool keep_connected_only = true;  // subject parts not touching the head are dropped

  template <class V>
  void visit(V& v) {
    v("margin_m", margin_m,
      "How far the tracked mesh's silhouette may lie from the subject's, metres at the head (converted to "
      "pixels per camera): the silhouette shrunk by this is subject whatever the clean plate says, and the "
      "clean plate alone decides within it.");
    v("keep_connected_only", keep_connected_only,
      "Keep only subject regions connected to the head (hair and shoulders are; a moved prop is not).");
  }
};

// Alpha at the subject's edge: with the clean plate, each pixel of a band
// around the edge is unmixed into subject colour and the known background
// (I = a F + (1 - a) B); then a guided filter.
struct EdgeOptions {
  int band_px = 3;                  // the band's half-width, pixels
  double min_contrast = 0.06;       // below this subject-background colour distance, alpha follows the mask
  int guided_filter_radius_px = 2;  // 0: off
  double guided_filter_eps = 1e-3;

  template <class V>
  void visit(V& v) {
    v("band_px", band_px, "Half-width of the band around the subject's edge where alpha is fractional, pixels.");
    v("min_contrast", min_contrast,
      "Where the subject's colour and the background's are closer than this (RGB distance, 0..1), alpha leans "
      "on the smoothed mask instead of unmixing.");
    v("guided_filter_radius_px", guided_filter_radius_px,
      "Radius of the guided filter that smooths alpha in the band along the image's edges; 0 turns it off.");
    v("guided_filter_eps", guided_filter_eps, "The guided filter's regulariser (larger: smoother).");
  }
};

struct MatteOptions {
  bool use_clean_plate = true;
  std::string clean_plate_take;  // empty: the capture's clean_plate take
  DifferenceOptions difference;
  MeshPriorOptions mesh;
  EdgeOptions edge;
  int max_work_width = 2048;  // wider photos are matted at 1/n of their size, alpha enlarged back
  int threads = 0;            // 0: all cores

  template <class V>
  void visit(V& v) {
    v("use_clean_plate", use_clean_plate,
      "Subtract the capture's clean plate (false: the tracked mesh alone, e.g. when the lighting changed since).");
    v("clean_plate_take", clean_plate_take,
      "The take of the empty studio to subtract; empty: the capture's clean_plate take. Without one, mattes "
      "come from the tracked mesh alone (with a warning).");
    v("difference", difference, "The difference from the clean plate.");
    v("mesh", mesh, "The tracked mesh's silhouette.");
    v("edge", edge, "Fractional alpha at the edge.");
    v("max_work_width", max_work_width,
      "Photos wider than this are matted at an integer fraction of their size (area-averaged) and the alpha "
      "enlarged back (bilinear): 6144 x 4096 is matted at 2048 x 1365, 9 times faster, its edge softened by "
      "about the factor in pixels. Raise it for sharper mattes of large photos.");
    v("threads", threads, "Worker threads; 0: all cores.");
  }
};

}  // namespace tega::matting
