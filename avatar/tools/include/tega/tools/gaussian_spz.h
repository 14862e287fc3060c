#pragma once
// World-space Gaussians (gaussian_ply.h) in Niantic's SPZ format, version 2,
// which web splat viewers (Spark, three.js based ones) read: a gzip stream of
// a 16-byte header and, for all Gaussians in turn, their positions (24-bit
// fixed point), opacities, DC colours, log scales, rotations and higher SH
// coefficients (8 bits each). About a tenth of the PLY's bytes; the layout and
// its quantisation byte by byte are in docs/render-eval-export.md#spz.
//
// SPZ stores points in a right-up-back frame (three.js, OpenGL); tega's world
// frame is OpenCV's right-down-front (as 3DGS PLYs are). The two differ by a
// half turn about x, which the writer applies (positions, rotations and the
// odd-in-y-and-z SH coefficients change sign) and the reader undoes.

#include <filesystem>

#include "tega/tools/gaussian_ply.h"

namespace tega::tools {

// Atomic. Values outside what SPZ can hold are clamped as SPZ does (log scales
// to [-10, 5.94], DC coefficients to ±3.33, higher SH coefficients to [-1, 1]);
// a position beyond SPZ's ±2048 m, or a non-finite value, throws tega::Error.
// `antialiased` sets the header's flag that tells viewers the Gaussians were
// trained with antialiased (Mip-Splatting) rasterization.
void write_gaussian_spz(const GaussianCloud& cloud, const std::filesystem::path& file, bool antialiased);

struct SpzCloud {
  GaussianCloud gaussians;  // float32, CPU, tega's frame
  bool antialiased = false;
};

// Reads SPZ version 2 (any fractional bits, SH degree 0 to 3). Throws
// tega::Error naming the file for anything else: not gzip, corrupt or
// truncated data, a bad magic number, another version, extensions.
SpzCloud read_gaussian_spz(const std::filesystem::path& file);

// Between tega's frame and SPZ's: positions and the y and z of quaternions
// change sign, as do the SH coefficients whose basis functions are odd in
// y and z together. Its own inverse.
GaussianCloud half_turn_about_x(const GaussianCloud& cloud);

}  // namespace tega::tools
