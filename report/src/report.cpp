#include "tega/report/report.h"

#include <functional>
#include <map>

#include "page.h"
#include "report_context.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "workspace_outputs.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

using SectionBuilder = std::function<Section(const StageOutput&, ReportContext&)>;

// The kinds whose outputs the page shows; others appear in the stage table only.
const std::map<std::string, SectionBuilder>& section_builders() {
  static const std::map<std::string, SectionBuilder> builders = {
      {"calibrate", calibration_section}, {"mvs", mvs_section},        {"track", tracking_section},
      {"matte", matting_section},         {"train", training_section}, {"eval", evaluation_section},
      {"render", renders_section}};
  return builders;
}

Section stages_section(const SubjectOutputs& subject) {
  Section section{"Stages", {}};
  Table table{{"stage", "kind", "state", "note"}, {}};
  for (const auto& stage : subject.stages) table.rows.push_back({stage.stage, stage.kind, stage.state, stage.reason});
  section.table(std::move(table));
  if (!subject.capture.empty())
    section.text(
        "Capture: " + subject.capture.string() +
        (subject.virtual_studio() ? " (the virtual studio's: every stage is scored against its ground truth)" : ""));
  return section;
}

// A stage without a committed shard: what `tega status` says of it.
Section not_run_section(const std::string& title, const StageOutput& stage) {
  Section section{title + " (" + stage.stage + ")", {}};
  section.text("Not run: " + stage.stage + " is " + stage.state +
               (stage.reason.empty() ? "" : " (" + stage.reason + ")") + ".");
  return section;
}

Section self_test_section(const ReportContext& context) {
  Section section{"Ground truth: the studio's self-test", {}};
  section.text(
      "Each stage's output scored against the virtual studio's truth, beside the target its issue or "
      "documentation states (docs/report.md#ground-truth-scores).");
  Table table{{"stage", "measure", "value", "target", "verdict"}, {}};
  for (const auto& s : context.scores) table.rows.push_back({s.stage, s.measure, s.value, s.target, s.verdict});
  if (!table.rows.empty()) section.table(std::move(table));
  for (const auto& error : context.score_errors) section.text("Not scored: " + error);
  if (context.scores.empty() && context.score_errors.empty())
    section.text("No stage with a ground truth to score has run.");
  return section;
}

SubjectReport subject_report(const SubjectOutputs& subject, const fs::path& workspace, const ReportOptions& options,
                             const fs::path& out) {
  ReportContext context{subject, options, out / subject.subject, {}, {}, {}};
  Page page{"tega report: " + subject.subject, {}};
  page.sections.push_back(stages_section(subject));
  page.sections.front().text("Workspace: " + workspace.string() + ".");
  for (const auto& stage : subject.stages) {
    const auto builder = section_builders().find(stage.kind);
    if (builder == section_builders().end()) continue;
    if (!stage.committed) {
      page.sections.push_back(not_run_section(builder->first, stage));
      continue;
    }
    try {
      Section section = builder->second(stage, context);
      section.title += " (" + stage.stage + ")";
      if (stage.state != "done")
        section.blocks.insert(
            section.blocks.begin(),
            Block{Block::Kind::text, "Note: this shard is " + stage.state + ": " + stage.reason + ".", {}, {}});
      page.sections.push_back(std::move(section));
    } catch (const std::exception& e) {
      Section section{stage.kind + " (" + stage.stage + ")", {}};
      section.text("Could not be read: " + std::string(e.what()));
      page.sections.push_back(std::move(section));
    }
  }
  if (context.scoring()) page.sections.push_back(self_test_section(context));
  return {subject.subject, page_markdown(page), page_html(page), std::move(context.figures)};
}

}  // namespace

Report build_report(const fs::path& workspace, const ReportOptions& options) {
  const std::string version =
      options.tool_version.empty() ? std::string("tega ") + TEGA_REPORT_VERSION : options.tool_version;
  const fs::path root = fs::absolute(workspace).lexically_normal();
  Report report{root, options.out.empty() ? root / "report" : fs::absolute(options.out).lexically_normal(), {}};
  for (const auto& subject : workspace_outputs(root, options.subjects, version)) {
    logging::info("report: %s", subject.subject.c_str());
    report.subjects.push_back(subject_report(subject, root, options, report.out));
  }
  return report;
}

std::vector<fs::path> write_report(const Report& report) {
  std::vector<fs::path> pages;
  fs::create_directories(report.out);
  for (const auto& subject : report.subjects) {
    StagedDirectory dir(report.out / subject.subject, true);
    write_text_atomic(dir.path() / "report.md", subject.markdown);
    write_text_atomic(dir.path() / "report.html", subject.html);
    for (const auto& figure : subject.figures) write_image(figure.image, dir.path() / figure.file);
    dir.commit();
    pages.push_back(report.out / subject.subject / "report.md");
  }
  return pages;
}

}  // namespace tega::report
