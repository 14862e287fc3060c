#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.h"
#include "heap.h"
#include "tega/core/error.h"
#include "tega/core/log.h"

namespace {

// The first argument that is not a flag: the command, since tega's own flags take no value.
std::string first_command(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] != '-') return argv[i];
  return "";
}

bool has_command(const CLI::App& app, const std::string& name) {
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; }))
    if (command->check_name(name)) return true;
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  tega::cli::keep_freed_memory_for_reuse();
  CLI::App app{"tega: multi-camera head capture to animatable 3D Gaussian head avatars.\n"
               "Run `tega <command> --help` for a command's options."};
  app.get_formatter()->column_width(44);
  app.set_version_flag("--version", std::string("tega ") + TEGA_VERSION);
  int verbosity = 1;
  app.add_flag_function("-v,--verbose", [&](int64_t n) { verbosity = 1 + static_cast<int>(n); },
                        "More log output (repeat for debug).");
  app.add_flag_function("-q,--quiet", [&](int64_t) { verbosity = 0; }, "Only warnings and errors.");
  app.require_subcommand(1);
  app.parse_complete_callback([&] { tega::init_logging(verbosity); });

  tega::cli::add_dataset_command(app);
  tega::cli::add_rig_command(app);
  tega::cli::add_ingest_command(app);
#ifdef TEGA_HAVE_SYNTH
  tega::cli::add_synth_command(app);
#endif
#ifdef TEGA_HAVE_CAPTURE
  tega::cli::add_capture_command(app);
#endif
#ifdef TEGA_HAVE_CALIBRATE
  tega::cli::add_calibrate_command(app);
#endif
#ifdef TEGA_HAVE_MVS
  tega::cli::add_mvs_command(app);
#endif
#ifdef TEGA_HAVE_TRACKING
  tega::cli::add_track_command(app);
#endif
#ifdef TEGA_HAVE_LANDMARKS
  tega::cli::add_landmarks_command(app);
#endif
#ifdef TEGA_HAVE_MATTING
  tega::cli::add_matte_command(app);
#endif
#ifdef TEGA_HAVE_TRAINER
  tega::cli::add_train_command(app);
#endif
#ifdef TEGA_HAVE_TOOLS
  tega::cli::add_render_command(app);
  tega::cli::add_eval_command(app);
  tega::cli::add_inspect_command(app);
  tega::cli::add_export_command(app);
#endif
#ifdef TEGA_HAVE_SERVE
  tega::cli::add_serve_command(app);
#endif
  tega::cli::add_run_command(app);
  tega::cli::add_status_command(app);
#ifdef TEGA_HAVE_REPORT
  tega::cli::add_report_command(app);
#endif

  // CLI11 answers --help before it objects to an unknown command, so that
  // `tega nosuch --help` would print the top help and succeed.
  if (const std::string command = first_command(argc, argv); !command.empty() && !has_command(app, command)) {
    std::cerr << "tega: error: unknown command '" << command << "' (`tega --help` lists the commands)\n";
    return 1;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const tega::Error& e) {
    std::cerr << "tega: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "tega: internal error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
