// `tega rig convert`: a rig between tega's JSON, COLMAP text and Multiface KRT
// (docs/rig-files.md).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>

#include "tega/core/log.h"
#include "tega/core/rig.h"

namespace tega::cli {
namespace {

enum class RigFormat { json, colmap, krt };

struct ConvertArgs {
  std::filesystem::path in, out;
  std::string in_format, out_format;  // empty: from the path
  int width = 0, height = 0;
  double colmap_metres_per_unit = 1.0;
};

// An explicit --in-format/--out-format wins; otherwise *.json is a rig file, a
// directory (existing, or written with a trailing '/') a COLMAP model, and
// anything else a KRT file.
RigFormat format_of(const std::filesystem::path& path, const std::string& named) {
  if (named == "json") return RigFormat::json;
  if (named == "colmap") return RigFormat::colmap;
  if (named == "krt") return RigFormat::krt;
  if (path.extension() == ".json") return RigFormat::json;
  if (!path.has_filename() || std::filesystem::is_directory(path)) return RigFormat::colmap;
  return RigFormat::krt;
}

void convert(const ConvertArgs& args, bool size_given) {
  const RigFormat from = format_of(args.in, args.in_format);
  const RigFormat to = format_of(args.out, args.out_format);
  if (from == RigFormat::krt && !size_given)
    throw CLI::ValidationError("--width/--height", "a KRT file holds no image size; give both");
  if (from != RigFormat::krt && size_given)
    throw CLI::ValidationError("--width/--height", "only a KRT input takes an image size");

  Rig rig;
  switch (from) {
    case RigFormat::json: rig = read_rig_json(args.in); break;
    case RigFormat::colmap: rig = read_colmap_text(args.in, args.colmap_metres_per_unit); break;
    case RigFormat::krt: rig = read_krt(args.in, args.width, args.height); break;
  }
  switch (to) {
    case RigFormat::json: write_rig_json(rig, args.out); break;
    case RigFormat::colmap: write_colmap_text(rig, args.out, args.colmap_metres_per_unit); break;
    case RigFormat::krt: write_krt(rig, args.out); break;
  }
  logging::info("wrote %zu cameras to %s", rig.cameras.size(), args.out.c_str());
}

}  // namespace

void add_rig_command(CLI::App& app) {
  CLI::App* rig = app.add_subcommand("rig", "Camera rig files (docs/rig-files.md).");
  rig->require_subcommand(1);
  CLI::App* convert_command = rig->add_subcommand(
      "convert",
      "Convert a rig between tega's rig JSON (*.json), a COLMAP text model (a directory) and a "
      "Multiface KRT file (any other name).");
  auto args = std::make_shared<ConvertArgs>();
  convert_command
      ->add_option("--in", args->in,
                   "Rig to read: a *.json rig file, a COLMAP text model directory, or a KRT file.")
      ->required();
  convert_command
      ->add_option("--out", args->out,
                   "Where to write: a *.json rig file, a directory (existing or ending in '/') for "
                   "a COLMAP text model, or any other name for a KRT file. Replaced atomically.")
      ->required();
  const std::vector<std::string> formats{"json", "colmap", "krt"};
  convert_command
      ->add_option("--in-format", args->in_format,
                   "Format of --in when its name does not tell: json, colmap or krt.")
      ->check(CLI::IsMember(formats));
  convert_command
      ->add_option("--out-format", args->out_format,
                   "Format of --out when its name does not tell: json, colmap or krt.")
      ->check(CLI::IsMember(formats));
  CLI::Option* width =
      convert_command
          ->add_option("--width", args->width,
                       "Image width in pixels of every camera; required for a KRT input, which "
                       "holds no image size.")
          ->check(CLI::PositiveNumber);
  CLI::Option* height = convert_command
                            ->add_option("--height", args->height,
                                         "Image height in pixels of every camera; required for a "
                                         "KRT input.")
                            ->check(CLI::PositiveNumber);
  width->needs(height);
  height->needs(width);
  convert_command
      ->add_option("--colmap-metres-per-unit", args->colmap_metres_per_unit,
                   "Metres per COLMAP length unit: COLMAP translations are multiplied by it on "
                   "reading and divided by it on writing. 1 for a model in metres, 0.001 for "
                   "millimetres.")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  convert_command->callback([args, width] { convert(*args, width->count() > 0); });
}

}  // namespace tega::cli
