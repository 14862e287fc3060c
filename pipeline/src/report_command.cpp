// `tega report WORKSPACE`: a page per subject of what each stage made, with
// the virtual studio's self-test (docs/report.md).

#include <iostream>
#include <memory>

#include "commands.h"
#include "tega/report/report.h"

namespace tega::cli {
namespace {

struct ReportArguments {
  std::string workspace;
  report::ReportOptions options;
  bool no_ground_truth = false;
};

void run_report(ReportArguments args) {
  args.options.score_ground_truth = !args.no_ground_truth;
  args.options.tool_version = std::string("tega ") + TEGA_VERSION;
  const report::Report built = report::build_report(args.workspace, args.options);
  for (const auto& page : report::write_report(built)) std::cout << page.string() << "\n";
}

}  // namespace

void add_report_command(CLI::App& app) {
  auto args = std::make_shared<ReportArguments>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write a page per subject (report.md, report.html, PNG plots) of what each stage of a workspace made; "
      "a virtual-studio capture's stages are scored against its ground truth (docs/report.md).");
  cmd->add_option("workspace", args->workspace, "A pipeline workspace (`tega run` made it).")->required();
  cmd->add_option("--out", args->options.out,
                  "Where the pages go: OUT/<subject>/report.md (default: WORKSPACE/report).");
  cmd->add_option("--subject", args->options.subjects, "Only this subject (repeatable; default: every subject).");
  cmd->add_flag("--no-ground-truth", args->no_ground_truth,
                "Do not score the stages against the virtual studio's truth.");
  cmd->add_option("--scored-frames", args->options.scored_frames_per_take,
                  "MVS meshes per take scored against the truth.")
      ->capture_default_str();
  cmd->add_option("--contact-sheet-views", args->options.contact_sheet_views, "Views on the contact sheet.")
      ->capture_default_str();
  cmd->callback([args] { run_report(*args); });
}

}  // namespace tega::cli
