// Renders: a contact sheet of a few views, each the render beside the
// dataset's photo of the same camera and frame (render's side_by_side/
// images), downscaled into one PNG. Renders without a photo (orbit cameras)
// are shown alone.

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "image_conversion.h"
#include "report_context.h"
#include "tega/core/error.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

// <dir>/<camera>/<frame>.png, sorted.
std::vector<fs::path> view_images(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& camera : fs::directory_iterator(dir)) {
    if (!camera.is_directory() || camera.path().filename() == "side_by_side") continue;
    for (const auto& file : fs::directory_iterator(camera.path()))
      if (file.path().extension() == ".png") files.push_back(file.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Views two to a row, each scaled to `view_width` and labelled camera/frame.
Image8 contact_sheet(const std::vector<fs::path>& views, int view_width) {
  const int columns = std::min<int>(2, int(views.size())), label_height = 22;
  std::vector<cv::Mat> tiles;
  int tile_height = 0;
  for (const auto& file : views) {
    const cv::Mat view = bgr_of(read_image_u8(file));
    cv::Mat tile;
    cv::resize(view, tile, {view_width, std::max(1, view.rows * view_width / view.cols)}, 0, 0, cv::INTER_AREA);
    tile_height = std::max(tile_height, tile.rows);
    tiles.push_back(tile);
  }
  const int rows = (int(tiles.size()) + columns - 1) / columns, gap = 8;
  cv::Mat sheet(rows * (tile_height + label_height + gap) + gap, columns * (view_width + gap) + gap, CV_8UC3,
                cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < tiles.size(); ++i) {
    const int x = gap + int(i % size_t(columns)) * (view_width + gap);
    const int y = gap + int(i / size_t(columns)) * (tile_height + label_height + gap);
    tiles[i].copyTo(sheet(cv::Rect(x, y + label_height, tiles[i].cols, tiles[i].rows)));
    const std::string name = views[i].parent_path().filename().string() + " / " + views[i].stem().string();
    cv::putText(sheet, name, {x, y + 15}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  return image_of(sheet);
}

}  // namespace

Section renders_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Renders", {}};
  const fs::path renders = artifact(stage, "renders");
  if (!fs::is_directory(renders)) throw Error(renders, "does not exist");
  std::vector<fs::path> views = view_images(renders / "side_by_side");
  const bool beside_photos = !views.empty();
  if (!beside_photos) views = view_images(renders);
  if (views.empty()) {
    section.text(context.link(renders) + "/ holds no PNG renders.");
    return section;
  }
  std::vector<fs::path> chosen;
  for (size_t i : spread(views.size(), size_t(std::max(1, context.options.contact_sheet_views))))
    chosen.push_back(views[i]);
  const int tile = std::max(16, context.options.contact_sheet_tile_width);
  section.text("Renders " + context.link(renders) + "/: " + std::to_string(chosen.size()) + " of " +
               std::to_string(views.size()) +
               (beside_photos ? " views, each the render (left) beside the dataset's photo (right)."
                              : " renders; none has a photo to compare with (orbit or other cameras)."));
  context.add_figure(section, "contact_sheet.png", contact_sheet(chosen, beside_photos ? 2 * tile : tile),
                     beside_photos ? "Renders beside the photos" : "Renders");
  return section;
}

}  // namespace tega::report
