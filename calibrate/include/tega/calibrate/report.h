#pragma once
// The calibration's outputs, written next to the rig (docs/calibration.md#the-report):
//   rig.json               the rig (tega's format)
//   rig.report.json        per camera: views, corners, RMS, coverage, outliers, movement against --init
//   rig.colmap/            the rig as a COLMAP text model
//   rig.krt                the rig as a Multiface KRT file
//   rig.residuals/<camera>.png   each corner's reprojection error, magnified; outliers in red
#include <filesystem>
#include <string>

#include "tega/calibrate/calibration.h"

namespace tega::calibrate {

void write_calibration(const Calibration& calibration, const std::filesystem::path& rig_file);

// The terminal summary: one line per camera, then the totals.
std::string calibration_summary(const Calibration& calibration);

}  // namespace tega::calibrate
