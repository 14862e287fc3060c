#pragma once
// The rig config of `tega capture` (docs/capture.md#the-rig-config): which
// cameras, with which settings, how frames are grouped into frame sets and
// how they are written.
#include <filesystem>
#include <string>
#include <vector>

namespace tega::capture {

// What every camera is set to before acquisition starts; each is applied,
// read back and compared (a camera that does not take a value refuses the
// take). A camera's own `settings` mapping overrides single fields.
struct CameraSettings {
  std::string pixel_format = "Mono8";
  int width = 0;     // 0: the sensor's full width (minus offset_x)
  int height = 0;    // 0: the sensor's full height (minus offset_y)
  int offset_x = 0;
  int offset_y = 0;
  double exposure_us = 10000;
  double gain = 0;
  double frame_rate = 30;  // free-run rate; the trigger rate for software (and simulated hardware) trigger
  int packet_size = 0;     // GigE Vision only; 0: negotiated (largest the path carries)
  int packet_delay_ns = 0; // GigE Vision only; inter-packet delay, spreads 13 cameras on one link
  bool packet_socket = true;  // GigE Vision only; false for loopback (simulated cameras), where Linux packet sockets see nothing
  std::string trigger_source = "Line0";  // hardware trigger input line
  std::string trigger_activation = "RisingEdge";
  template <class V>
  void visit(V& v) {
    v("pixel_format", pixel_format, "GenICam pixel format: Mono8, Mono16, RGB8, BayerRG8, BayerBG8, BayerGB8, BayerGR8, Bayer*16.");
    v("width", width, "Region of interest width in pixels; 0 = full sensor.");
    v("height", height, "Region of interest height in pixels; 0 = full sensor.");
    v("offset_x", offset_x, "Region of interest left edge in pixels.");
    v("offset_y", offset_y, "Region of interest top edge in pixels.");
    v("exposure_us", exposure_us, "Exposure time in microseconds.");
    v("gain", gain, "Analog gain in the camera's own units (dB on most cameras).");
    v("frame_rate", frame_rate, "Frames per second: the free-run rate, or the software trigger rate.");
    v("packet_size", packet_size, "GigE Vision packet size in bytes; 0 = negotiate the largest the network carries.");
    v("packet_delay_ns", packet_delay_ns, "GigE Vision inter-packet delay in nanoseconds (0 = none).");
    v("packet_socket", packet_socket, "GigE Vision: receive through a Linux packet socket (faster); false on loopback.");
    v("trigger_source", trigger_source, "Hardware trigger input, e.g. Line0, Line1.");
    v("trigger_activation", trigger_activation, "Hardware trigger edge: RisingEdge or FallingEdge.");
  }
};

struct CameraConfig {
  std::string name;    // the folder name in the take, e.g. cam00
  std::string serial;  // the camera's serial number, as `tega capture list` shows it
  CameraSettings settings;  // the rig's settings, with this camera's own `settings` keys on top
  template <class V>
  void visit(V& v) {
    v("name", name, "Camera name: the take's folder for its images (e.g. cam00).");
    v("serial", serial, "Serial number (see `tega capture list`).");
    v("settings", settings, "Settings of this camera that differ from the rig's `settings`.");
  }
};

struct SyncOptions {
  std::string group_by = "timestamp";     // timestamp | frame_id
  std::string timestamp_source = "host";  // host | device
  double tolerance_ms = 0;                // 0: half a frame period
  std::string incomplete_sets = "drop";   // drop | keep
  double set_timeout_ms = 500;
  double camera_timeout_ms = 3000;
  bool stop_on_camera_loss = false;
  template <class V>
  void visit(V& v) {
    v("group_by", group_by,
      "What puts frames of different cameras into one frame set: timestamp, or frame_id (exact under a hardware "
      "trigger when every camera is armed before the first pulse).");
    v("timestamp_source", timestamp_source,
      "host (arrival time on this computer) or device (camera clocks; only when they are PTP-synchronised).");
    v("tolerance_ms", tolerance_ms, "Largest timestamp difference within one frame set; 0 = half a frame period.");
    v("incomplete_sets", incomplete_sets,
      "A frame set missing a camera is counted and reported, then: drop (not written) or keep (written, the gap "
      "listed in take.json's `missing`).");
    v("set_timeout_ms", set_timeout_ms, "How long a frame set waits for a late camera before it is closed incomplete.");
    v("camera_timeout_ms", camera_timeout_ms,
      "A camera that delivers nothing for this long while acquiring is declared lost.");
    v("stop_on_camera_loss", stop_on_camera_loss,
      "Stop the take when a camera is lost (default: go on with the others and record the gap).");
  }
};

struct WriterOptions {
  std::string format = "png";  // png | tiff
  int png_compression = 1;     // zlib level: 1 keeps up with 13 cameras; 9 is ~3x slower for ~10% smaller files
  int threads = 0;             // 0: one per hardware thread
  int queue_depth = 16;        // frame sets per camera waiting for the writer
  bool debayer = false;
  double min_free_mb = 512;
  template <class V>
  void visit(V& v) {
    v("format", format, "Image files: png or tiff (tiff needs a build with OpenImageIO). Lossless either way.");
    v("png_compression", png_compression, "PNG zlib level 0-9; 1 is fast enough for the rig, 9 is smallest.");
    v("threads", threads, "Writer threads; 0 = one per hardware thread.");
    v("queue_depth", queue_depth,
      "Frames per camera waiting to be written; when a camera's queue is full the whole frame set is dropped "
      "(and counted).");
    v("debayer", debayer, "Write Bayer frames as RGB (OpenCV demosaicing) instead of the raw mosaic.");
    v("min_free_mb", min_free_mb, "Refuse to start, and stop the take, when the disk has less free space than this.");
  }
};

struct RigConfig {
  std::string source = "aravis";  // aravis | fake
  CameraSettings settings;
  std::vector<CameraConfig> cameras;
  SyncOptions sync;
  WriterOptions writer;
  std::filesystem::path file;  // where it was loaded from (for messages)
  template <class V>
  void visit(V& v) {
    v("source", source,
      "aravis: cameras Aravis discovers (GigE Vision, USB3 Vision, and simulated GigE cameras); fake: one in-process "
      "Aravis simulated camera per entry (tests, demos).");
    v("settings", settings, "Settings of every camera.");
    v("cameras", cameras, "The cameras of the rig, in order.");
    v("sync", sync, "Grouping frames into frame sets.");
    v("writer", writer, "Writing images.");
  }
};

// Loads and checks a rig config: unknown keys, duplicate names or serials,
// unknown enum values and impossible numbers are errors naming the file.
RigConfig load_rig_config(const std::filesystem::path& file);
void validate_rig_config(const RigConfig& rig);

}  // namespace tega::capture
