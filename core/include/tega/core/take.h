#pragma once
// The capture layout (docs/layouts.md#capture-takes), read, written and checked
// by one piece of code whether a camera rig (`tega capture`) or the virtual
// studio (`tega synth`) recorded it:
//
//   CAPTURE/
//     capture.json                  cameras, image size, the takes and their frame counts
//     takes/<take>/take.json        one take: TakeInfo below
//     takes/<take>/<camera>/<frame>.png   (or .tif/.tiff) one image per camera and frame

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace tega {

// One take: takes/<take>/take.json plus one image per camera and frame.
struct TakeInfo {
  std::string name;
  std::string kind;  // clean_plate | calibration | performance
  std::vector<std::string> cameras;
  int frames = 0;
  double fps = 0;
  std::string images = "{camera}/{frame:06d}.png";  // relative to the take folder; also .tif/.tiff
  std::string pixel_format = "RGB8";  // GenICam name: RGB8, Mono8, Mono16, BayerRG8, BayerBG8, BayerGB8, BayerGR8, BayerRG16...
  int bit_depth = 8;                  // 8 or 16
  std::map<std::string, std::vector<int>> missing;  // camera -> sorted frame indices that have no image (a recorded gap)
  std::filesystem::path folder;                     // set by read_take; not stored in the JSON

  int channels() const;  // 3 for RGB/BGR formats, else 1 (Mono and raw Bayer)
  std::filesystem::path image_path(const std::string& camera, int frame) const;  // folder / pattern filled in
  bool has_image(const std::string& camera, int frame) const;                   // false when listed in missing
};

// Throws tega::Error naming take.json and the bad or missing field.
TakeInfo read_take(const std::filesystem::path& take_folder);
// Writes take_folder/take.json atomically.
void write_take(const TakeInfo& take, const std::filesystem::path& take_folder);
// Checks take.json's fields and every image the take lists: it exists (unless
// missing); for PNGs, all of one camera have one size and the channel count
// and bit depth of pixel_format/bit_depth. TIFFs are only checked to exist:
// read_image_header reads PNG alone. Throws tega::Error naming the first
// offending file.
void validate_take(const TakeInfo& take);

// A command's `--frames`: "A:B" (B exclusive), "A:" or "A" into [first, end), end -1 for "to the
// take's end". Throws tega::Error.
void parse_frame_range(const std::string& text, int& first, int& end);

struct CaptureTake {
  std::string name, kind;
  int frames = 0;
};

struct CaptureInfo {
  std::filesystem::path root;
  std::vector<std::string> cameras;
  int width = 0, height = 0;
  std::vector<CaptureTake> takes;
  std::string rig;  // relative path of the rig file, "" when none
  std::string generator;

  // `chosen` when given, else the capture's rig file (rig.json when it names none).
  std::filesystem::path rig_file(const std::filesystem::path& chosen = {}) const;
  // `chosen` when given, else every performance take; throws tega::Error
  // naming capture.json when that leaves none (`purpose`: "to track", ...).
  std::vector<std::string> performance_takes(const std::vector<std::string>& chosen, const std::string& purpose) const;
};

// Reads capture.json (format "tega-capture", version 1). Throws tega::Error naming it.
CaptureInfo read_capture(const std::filesystem::path& capture_root);
// Every take capture.json lists has a folder whose take.json agrees with it
// (kind, frames, cameras among the capture's) and validates.
void validate_capture(const std::filesystem::path& capture_root);
// Adds or replaces the take's entry in capture_root/capture.json, creating the
// file (format, version, generator, cameras, width, height) when absent. Every
// other key already there is kept; cameras new to the capture are appended so
// that it keeps validating. Atomic.
void record_take_in_capture(const std::filesystem::path& capture_root, const TakeInfo& take, int width, int height,
                            const std::string& generator);

}  // namespace tega
