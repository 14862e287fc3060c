#include "tega/pipeline/config.h"
#include "tega/pipeline/gpus.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <set>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/pipeline/stage_kinds.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
namespace {

std::string line_of(const YAML::Node& node) {
  const auto mark = node.Mark();
  return mark.is_null() ? "" : " (line " + std::to_string(mark.line + 1) + ")";
}

class Reader {
 public:
  explicit Reader(fs::path source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    throw Error(source_, what + line_of(at));
  }

  void require_map(const YAML::Node& node, const std::string& where) const {
    if (!node.IsMap()) fail(node, "'" + where + "' must be a mapping");
  }

  void check_keys(const YAML::Node& map, const std::string& where, const std::vector<std::string>& known) const {
    for (const auto& entry : map) {
      const auto key = entry.first.as<std::string>();
      if (std::find(known.begin(), known.end(), key) != known.end()) continue;
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw Error(source_, "unknown key '" + (where.empty() ? key : where + "." + key) + "'" + line_of(entry.first) +
                               "; known keys" + (where.empty() ? "" : " of '" + where + "'") + ": " + list);
    }
  }

  std::string scalar(const YAML::Node& node, const std::string& where) const {
    if (!node.IsScalar()) fail(node, "'" + where + "' must be a string");
    return node.as<std::string>();
  }

  std::vector<std::string> string_list(const YAML::Node& node, const std::string& where) const {
    if (node.IsScalar()) return {node.as<std::string>()};
    if (!node.IsSequence()) fail(node, "'" + where + "' must be a list of names");
    std::vector<std::string> out;
    for (const auto& item : node) out.push_back(scalar(item, where));
    return out;
  }

  const fs::path& source() const { return source_; }

 private:
  fs::path source_;
};

YAML::Node parse_yaml(const std::string& text, const fs::path& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(source, "is not valid YAML: " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
}

// Maps with sorted keys, quoted scalars kept quoted: equal options give equal
// text, which is what a shard's fingerprint hashes.
void emit_canonical(YAML::Emitter& out, const YAML::Node& node) {
  if (node.IsMap()) {
    // Sort the keys, not the nodes: assigning a YAML::Node overwrites the node it refers to.
    std::vector<std::string> keys;
    for (const auto& e : node) keys.push_back(e.first.as<std::string>());
    std::sort(keys.begin(), keys.end());
    out << YAML::BeginMap;
    for (const auto& key : keys) {
      out << YAML::Key << key << YAML::Value;
      emit_canonical(out, node[key]);
    }
    out << YAML::EndMap;
  } else if (node.IsSequence()) {
    out << YAML::Flow << YAML::BeginSeq;
    for (const auto& item : node) emit_canonical(out, item);
    out << YAML::EndSeq;
  } else if (node.IsScalar()) {
    if (node.Tag() == "!") out << YAML::DoubleQuoted;
    out << node.Scalar();
  } else {
    out << YAML::Null;
  }
}

std::string canonical_yaml(const YAML::Node& node) {
  if (!node || node.IsNull()) return "";
  YAML::Emitter out;
  emit_canonical(out, node);
  return std::string(out.c_str()) + "\n";
}

// `overlay` merged into `base`: mappings merge key by key, anything else replaces.
YAML::Node merged(const YAML::Node& base, const YAML::Node& overlay) {
  if (!base || base.IsNull()) return YAML::Clone(overlay);
  if (!overlay || overlay.IsNull()) return YAML::Clone(base);
  if (!base.IsMap() || !overlay.IsMap()) return YAML::Clone(overlay);
  YAML::Node out = YAML::Clone(base);
  for (const auto& e : overlay) {
    const auto key = e.first.as<std::string>();
    out[key] = merged(out[key], e.second);
  }
  return out;
}

fs::path resolve(const fs::path& base_dir, const std::string& path) {
  return (base_dir / path).lexically_normal();
}

// The section of an options file that a kind's command reads.
std::string options_section_of(const std::string& kind_name) {
  const StageKind* kind = find_stage_kind(kind_name);
  return kind ? kind->options_section : "";
}

// `claimed_sections` collects the top-level keys of the config itself that a
// stage reads its options from (`options_file` naming the config).
StageConfig read_stage(const Reader& r, const std::string& name, const YAML::Node& node, const fs::path& base_dir,
                       const YAML::Node& config_root, std::vector<std::string>& claimed_sections) {
  const std::string where = "stages." + name;
  StageConfig stage;
  stage.name = name;
  stage.kind = name;
  if (node.IsNull()) return stage;
  r.require_map(node, where);
  r.check_keys(node, where, {"kind", "after", "options", "options_file", "frames_per_job", "gpus_per_job",
                                  "jobs_per_gpu"});
  if (node["kind"]) stage.kind = r.scalar(node["kind"], where + ".kind");
  // A whole number of at least `least`; else an error saying what the key must be.
  const auto whole_number = [&](const char* key, int least, const std::string& meaning) {
    const std::string text = r.scalar(node[key], where + "." + key);
    if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos ||
        std::stoi(text) < least)
      r.fail(node[key], where + "." + key + " must be " + meaning);
    return std::stoi(text);
  };
  if (node["frames_per_job"])
    stage.frames_per_job = whole_number("frames_per_job", 0, "a whole number of frames, 0 for one job");
  if (node["gpus_per_job"])
    stage.gpus_per_job = whole_number("gpus_per_job", 1, "a whole number of GPUs, at least 1");
  if (node["jobs_per_gpu"])
    stage.jobs_per_gpu = whole_number("jobs_per_gpu", 1, "a whole number of jobs, at least 1");
  if (node["after"]) stage.after = r.string_list(node["after"], where + ".after");
  YAML::Node options;
  if (node["options_file"]) {
    const fs::path file = resolve(base_dir, r.scalar(node["options_file"], where + ".options_file"));
    const bool is_config_itself = fs::exists(file) && fs::exists(r.source()) && fs::equivalent(file, r.source());
    const YAML::Node document = is_config_itself ? config_root : parse_yaml(read_text_file(file), file);
    const std::string section = options_section_of(stage.kind);
    options.reset(section.empty() ? document : document[section]);
    if (!section.empty()) {
      if (!options) throw Error(file, "has no '" + section + "' section (the options of stage '" + name + "')");
      if (is_config_itself) claimed_sections.push_back(section);
    }
    if (!options.IsNull() && !options.IsMap()) throw Error(file, "must be a mapping of option names to values");
  }
  if (node["options"]) {
    if (!node["options"].IsNull()) r.require_map(node["options"], where + ".options");
    options.reset(merged(options, node["options"]));  // reset: `options` may alias the config's own section
  }
  stage.options_yaml = canonical_yaml(options);
  return stage;
}

SubjectConfig read_subject(const Reader& r, const std::string& name, const YAML::Node& node,
                           const std::set<std::string>& stage_names, const fs::path& base_dir) {
  const std::string where = "subjects." + name;
  SubjectConfig subject;
  subject.name = name;
  if (node.IsNull()) return subject;
  r.require_map(node, where);
  r.check_keys(node, where, {"capture", "options"});
  if (node["capture"]) subject.capture = resolve(base_dir, r.scalar(node["capture"], where + ".capture"));
  if (const auto options = node["options"]) {
    r.require_map(options, where + ".options");
    for (const auto& e : options) {
      const auto stage = e.first.as<std::string>();
      if (!stage_names.count(stage)) r.fail(e.first, "'" + where + ".options." + stage + "' names no stage");
      r.require_map(e.second, where + ".options." + stage);
      subject.stage_options[stage] = canonical_yaml(e.second);
    }
  }
  return subject;
}

// Shard names become directory names.
void check_name(const Reader& r, const YAML::Node& at, const std::string& what, const std::string& name) {
  const bool ok = !name.empty() && name[0] != '.' &&
                  std::all_of(name.begin(), name.end(), [](unsigned char c) {
                    return std::isalnum(c) || c == '_' || c == '-' || c == '.';
                  });
  if (!ok) r.fail(at, what + " '" + name + "' must be letters, digits, '_', '-' or '.' (not first)");
}

}  // namespace

std::string PipelineConfig::options_for(const StageConfig& stage, const SubjectConfig& subject) const {
  const auto overlay = subject.stage_options.find(stage.name);
  if (overlay == subject.stage_options.end()) return stage.options_yaml;
  return canonical_yaml(merged(YAML::Load(stage.options_yaml), YAML::Load(overlay->second)));
}

PipelineConfig parse_pipeline_config(const std::string& text, const fs::path& source, const fs::path& base_dir) {
  const Reader r(source);
  const YAML::Node root = parse_yaml(text, source);
  if (!root.IsMap()) throw Error(source, "must be a mapping with 'workspace' and 'stages'");

  PipelineConfig config;
  config.source = source;
  config.base_dir = fs::absolute(base_dir).lexically_normal();
  config.text = text;
  if (!root["workspace"]) throw Error(source, "needs 'workspace', the directory that holds the stages' outputs");
  config.workspace = resolve(config.base_dir, r.scalar(root["workspace"], "workspace"));

  const YAML::Node stages = root["stages"];
  std::set<std::string> stage_names;
  std::vector<std::string> known_keys = {"description", "workspace", "subjects", "stages", "gpus"};
  if (root["gpus"]) {
    config.gpus = r.string_list(root["gpus"], "gpus");
    check_gpu_list(*config.gpus, source.string() + ": gpus");
  }
  if (stages && stages.IsMap()) {
    for (const auto& e : stages) {
      const auto name = e.first.as<std::string>();
      check_name(r, e.first, "stage name", name);
      if (name == "logs") r.fail(e.first, "stage name 'logs' is reserved for the workspace's log folder");
      config.stages.push_back(read_stage(r, name, e.second, config.base_dir, root, known_keys));
      stage_names.insert(name);
    }
  }
  r.check_keys(root, "", known_keys);
  if (config.stages.empty()) throw Error(source, "needs 'stages', a mapping of stage names to stage sections");

  if (const YAML::Node subjects = root["subjects"]) {
    r.require_map(subjects, "subjects");
    for (const auto& e : subjects) {
      const auto name = e.first.as<std::string>();
      check_name(r, e.first, "subject name", name);
      config.subjects.push_back(read_subject(r, name, e.second, stage_names, config.base_dir));
    }
  }
  if (config.subjects.empty()) config.subjects.push_back({"default", {}, {}});
  return config;
}

PipelineConfig load_pipeline_config(const fs::path& file) {
  return parse_pipeline_config(read_text_file(file), file, fs::absolute(file).parent_path());
}

std::string options_file_text(const std::string& options_yaml, const std::string& section) {
  if (section.empty()) return options_yaml;
  YAML::Node wrapped;
  wrapped[section] = options_yaml.empty() ? YAML::Node(YAML::NodeType::Map) : YAML::Load(options_yaml);
  return canonical_yaml(wrapped);
}

std::vector<std::string> option_keys(const std::string& options_yaml) {
  std::vector<std::string> keys;
  if (options_yaml.empty()) return keys;
  for (const auto& e : YAML::Load(options_yaml)) keys.push_back(e.first.as<std::string>());
  return keys;
}

std::vector<std::string> option_flags(const std::string& options_yaml) {
  std::vector<std::string> flags;
  if (options_yaml.empty()) return flags;
  for (const auto& e : YAML::Load(options_yaml)) {
    std::string flag = "--" + e.first.as<std::string>();
    std::replace(flag.begin(), flag.end(), '_', '-');
    const YAML::Node& value = e.second;
    if (value.IsSequence()) {
      for (const auto& item : value) flags.insert(flags.end(), {flag, item.as<std::string>()});
    } else if (value.IsScalar()) {
      const std::string text = value.as<std::string>();
      if (value.Tag() != "!" && (text == "true" || text == "false")) {
        if (text == "true") flags.push_back(flag);
      } else {
        flags.insert(flags.end(), {flag, text});
      }
    } else if (!value.IsNull()) {
      throw Error("option '" + e.first.as<std::string>() + "' is a mapping, which no command-line flag takes");
    }
  }
  return flags;
}

std::optional<std::string> scalar_option(const std::string& options_yaml, const std::string& dotted_key) {
  if (options_yaml.empty()) return std::nullopt;
  YAML::Node node = YAML::Load(options_yaml);
  size_t begin = 0;
  while (true) {
    const size_t dot = dotted_key.find('.', begin);
    const std::string part = dotted_key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    if (!node.IsMap() || !node[part]) return std::nullopt;
    node.reset(node[part]);  // rebinds; assignment would overwrite the parent's data
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  if (!node.IsScalar()) return std::nullopt;
  return node.as<std::string>();
}

}  // namespace tega::pipeline
