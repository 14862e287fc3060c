// `tega capture`: records takes from the GenICam rig (docs/capture.md).
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "stage_options.h"
#include "tega/capture/recorder.h"
#include "tega/capture/session.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/core/take.h"

namespace tega::cli {

namespace {

struct CaptureArguments {
  std::string rig, take, kind = "performance", out, trigger = "hardware", preview, config, capture;
  std::vector<std::string> overrides;
  std::optional<int> frames;
  std::optional<double> seconds;
};

capture::RigConfig load_rig(const CaptureArguments& args) {
  if (args.rig.empty()) throw Error("--rig is required: the rig config (docs/capture.md#the-rig-config)");
  capture::RigConfig rig = capture::load_rig_config(args.rig);
  apply_overrides(rig, args.overrides);
  std::vector<std::string> rig_wide_settings;  // reach every camera
  for (const auto& kv : args.overrides)
    if (kv.rfind("settings.", 0) == 0) rig_wide_settings.push_back(kv);
  for (auto& camera : rig.cameras) apply_overrides(camera, rig_wide_settings);
  capture::validate_rig_config(rig);
  return rig;
}

void print_outcome(const capture::TakeOutcome& o) {
  std::printf("%s: %d frame sets in %.1f s (%s), %.1f MB\n", o.folder.c_str(), o.frames, o.seconds,
              o.stop_reason.c_str(), o.bytes / 1e6);
  std::printf("  frame sets: %lld seen, %lld incomplete, %lld incomplete dropped, %lld dropped (writer behind)\n",
              (long long)o.sets_seen, (long long)o.incomplete_sets, (long long)o.incomplete_dropped,
              (long long)o.writer_full_dropped);
  for (const auto& c : o.cameras) {
    std::printf("  %-10s %llu received, %llu written, %llu stream failures, %llu underruns, %llu late%s\n",
                c.name.c_str(), (unsigned long long)c.frames_received, (unsigned long long)c.frames_written,
                (unsigned long long)c.stream_failures, (unsigned long long)c.stream_underruns,
                (unsigned long long)c.late_frames, c.lost ? ("  LOST: " + c.lost_reason).c_str() : "");
  }
}

void add_list(CLI::App& capture) {
  auto* cmd = capture.add_subcommand("list", "List the cameras Aravis sees: vendor, model, serial, interface, address.");
  cmd->callback([] {
    const auto cameras = capture::list_cameras();
    if (cameras.empty()) {
      std::cout << "no cameras found (GigE Vision cameras must be on a reachable subnet)\n";
      return;
    }
    std::printf("%-20s %-24s %-16s %-10s %s\n", "vendor", "model", "serial", "interface", "address");
    for (const auto& c : cameras)
      std::printf("%-20s %-24s %-16s %-10s %s\n", c.vendor.c_str(), c.model.c_str(), c.serial.c_str(),
                  c.interface.c_str(), c.address.c_str());
  });
}

void add_check(CLI::App& capture, const std::shared_ptr<CaptureArguments>& args) {
  auto* cmd = capture.add_subcommand(
      "check", "Open every camera of the rig, apply and read back its settings, grab one frame set, report.");
  cmd->add_option("--rig", args->rig, "Rig config (YAML).");
  cmd->add_option("--trigger", args->trigger, "hardware (default), software or free.")
      ->check(CLI::IsMember({"hardware", "software", "free"}));
  cmd->add_option("--set", args->overrides, "Override one rig option, e.g. --set settings.exposure_us=8000.");
  cmd->callback([args] {
    const auto report = capture::check_rig(load_rig(*args), capture::parse_trigger(args->trigger));
    std::cout << report.dump(2) << "\n";
  });
}

void add_session(CLI::App& capture, const std::shared_ptr<CaptureArguments>& args) {
  auto* cmd = capture.add_subcommand(
      "session", "Record every take a session config lists into one capture (the `capture` pipeline stage).");
  cmd->add_option("--config", args->config, "YAML file whose `capture` section lists the rig and the takes.")
      ->required();
  cmd->add_option("--out", args->out, "Capture folder to write into.")->required();
  cmd->callback([args] {
    capture::SessionOptions options;
    load_options(options, args->config, "capture");
    capture::run_session(options, args->out);
  });
}

void add_validate(CLI::App& capture, const std::shared_ptr<CaptureArguments>& args) {
  auto* cmd = capture.add_subcommand(
      "validate", "Check a capture the way later stages read it: capture.json, every take.json, every image.");
  cmd->add_option("--capture", args->capture, "Capture folder.")->required();
  cmd->callback([args] {
    validate_capture(args->capture);
    const auto info = read_capture(args->capture);
    std::printf("%s: valid, %zu cameras, %zu takes\n", args->capture.c_str(), info.cameras.size(), info.takes.size());
    for (const auto& t : info.takes) std::printf("  %-20s %-12s %d frames\n", t.name.c_str(), t.kind.c_str(), t.frames);
  });
}

}  // namespace

void add_capture_command(CLI::App& app) {
  auto args = std::make_shared<CaptureArguments>();
  auto* cmd = app.add_subcommand(
      "capture",
      "Record a take from the GenICam rig (Aravis) into CAPTURE/takes/<take>/ (docs/capture.md); "
      "or list cameras, check a rig, record a session, validate a capture.");
  cmd->require_subcommand(0, 1);
  cmd->add_option("--rig", args->rig, "Rig config (YAML): cameras by serial, settings, sync, writer.");
  cmd->add_option("--take", args->take, "Take name: the folder under CAPTURE/takes/.");
  cmd->add_option("--kind", args->kind, "performance (default), calibration or clean_plate.");
  cmd->add_option("--out", args->out, "Capture folder (created if needed; capture.json lists its takes).");
  auto* frames = cmd->add_option("--frames", args->frames, "Stop after this many frame sets.");
  cmd->add_option("--seconds", args->seconds, "Stop after this many seconds.")->excludes(frames);
  cmd->add_option("--trigger", args->trigger,
                  "hardware (default; cameras wait on their trigger line), software or free (free-run). "
                  "Only hardware synchronises the rig.")
      ->check(CLI::IsMember({"hardware", "software", "free"}));
  cmd->add_option("--preview", args->preview, "Rewrite this PNG with a contact sheet of the latest frame set every 3 s.");
  cmd->add_option("--set", args->overrides, "Override one rig option, e.g. --set sync.incomplete_sets=keep.");
  add_list(*cmd);
  add_check(*cmd, args);
  add_session(*cmd, args);
  add_validate(*cmd, args);
  cmd->callback([cmd, args] {
    if (!cmd->get_subcommands().empty()) return;
    if (args->take.empty() || args->out.empty()) throw Error("tega capture needs --take and --out (and --rig)");
    capture::TakeRequest request;
    request.name = args->take;
    request.kind = args->kind;
    request.frames = args->frames.value_or(0);
    request.seconds = args->seconds.value_or(0);
    request.trigger = capture::parse_trigger(args->trigger);
    request.preview = args->preview;
    const auto outcome = capture::record_take(load_rig(*args), request, args->out);
    print_outcome(outcome);
    if (!outcome.error.empty()) throw Error(outcome.folder, "the take stopped on a write error: " + outcome.error +
                                                                " (what was written is kept and listed)");
  });
}

}  // namespace tega::cli
