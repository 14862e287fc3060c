#pragma once
// A take's images as the cameras recorded them (docs/layouts.md#capture-takes),
// made RGB or grey whatever the take's pixel format: RGB, BGR, Mono, or raw
// Bayer mosaics (GenICam BayerRG, BayerBG, BayerGB, BayerGR) demosaiced. Every
// stage that reads a take reads it through here, so that there is one mapping
// from GenICam's Bayer names to the demosaicing.
// Full-size demosaicing is OpenCV's; a build without OpenCV throws tega::Error
// where it is needed (the half-size path needs nothing).

#include <cstdint>
#include <filesystem>
#include <string>

#include "tega/core/image.h"
#include "tega/core/take.h"

namespace tega {

// Whether a GenICam pixel format is a raw Bayer mosaic (Bayer<pattern><bits>).
bool is_bayer(const std::string& pixel_format);

// Whether this build demosaics at full size (it has OpenCV).
bool demosaicing_available();

// Demosaics a mosaic of width x height samples of 8 or 16 bits
// (bytes_per_sample 1 or 2, rows packed) into interleaved RGB of the same
// depth at `rgb` (width x height x 3 samples). Throws tega::Error for a
// format that is not Bayer.
void demosaic(const void* mosaic, int width, int height, int bytes_per_sample, const std::string& pixel_format,
              void* rgb);

// An 8-bit mosaic as RGB (bilinear demosaicing).
Image8 debayer(const Image8& raw, const std::string& pixel_format);

// An 8-bit mosaic as one grey channel, without moving a pixel (what corner
// detection reads).
Image8 debayer_grey(const Image8& raw, const std::string& pixel_format);

// The mosaic demosaiced straight to half its size, one pixel per 2 x 2 quad:
// green is the mean of the quad's two greens, red and blue are interpolated
// (bilinearly between the four nearest samples of each) to the quad's centre,
// so that the three colours line up. A third of the cost of debayer() plus an
// area halving, for stages that keep half-size images.
// Throws tega::Error for an unknown format or an odd size.
Image8 debayer_half(const Image8& raw, const std::string& pixel_format);

// An 8-bit grey, grey + alpha, RGB or RGBA image as RGB (alpha dropped).
Image8 rgb_of(const Image8& image);

// Rec. 601 luma of an RGB (or grey) 8-bit image, in [0, 1].
ImageF grey_of(const Image8& image);

// A recorded image (as read from `file`) as 8-bit RGB by the take's pixel
// format, at 1/downsample of its size (area-averaged, the remainder dropped;
// a raw mosaic is demosaiced straight to half size where the factor is even,
// so that the full-size RGB is never made). Throws tega::Error naming the file
// when its channels do not fit the format.
Image8 recorded_rgb(const Image8& recorded, const std::string& pixel_format, const std::filesystem::path& file,
                    int downsample = 1);

// The image of `camera` in `frame` of `take`, read and made RGB as above.
// Throws tega::Error naming the file when it is missing, unreadable or does
// not fit the take's pixel format.
Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int downsample = 1);

// The same, checked first to be the rig camera's size: width x height.
Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height,
                         int downsample = 1);

}  // namespace tega
