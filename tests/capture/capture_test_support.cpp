#include "capture_test_support.h"

#include <fstream>
#include <sstream>

namespace tega::test {

capture::RigConfig fake_rig(int cameras, int width, int height, double frame_rate) {
  capture::RigConfig rig;
  rig.file = "test-rig.yaml";
  rig.source = "fake";
  rig.settings.width = width;
  rig.settings.height = height;
  rig.settings.frame_rate = frame_rate;
  rig.writer.threads = 2;
  for (int i = 0; i < cameras; ++i) {
    char name[16], serial[16];
    std::snprintf(name, sizeof name, "cam%02d", i);
    std::snprintf(serial, sizeof serial, "TEGA%02d", i);
    rig.cameras.push_back({name, serial, rig.settings});
  }
  return rig;
}

std::vector<std::map<std::string, std::string>> read_frame_sets(const std::filesystem::path& take_folder) {
  std::ifstream in(take_folder / "frame_sets.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream r(line);
    std::string cell;
    for (size_t i = 0; i < header.size(); ++i) {
      if (!std::getline(r, cell, ',')) cell.clear();
      row[header[i]] = cell;
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace tega::test
