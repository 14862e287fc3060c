#pragma once
// Each subcommand adds itself to the app. A command's callback parses nothing
// itself beyond CLI11's options and calls the stage library.

#include <CLI/CLI.hpp>

namespace tega::cli {
void add_synth_command(CLI::App& app);
void add_dataset_command(CLI::App& app);
void add_rig_command(CLI::App& app);
void add_ingest_command(CLI::App& app);
void add_capture_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
void add_mvs_command(CLI::App& app);
void add_track_command(CLI::App& app);
void add_landmarks_command(CLI::App& app);
void add_matte_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_inspect_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_serve_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_status_command(CLI::App& app);
void add_report_command(CLI::App& app);
}  // namespace tega::cli
