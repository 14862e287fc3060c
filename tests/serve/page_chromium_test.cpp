// The page in headless Chromium (software WebGL: SwiftShader) against
// `tega render`: `tega serve` on the tiny run, the page in still mode renders
// a dataset frame from a dataset camera, and its image must match tega's
// render of the same frame and camera to 30 dB inside the head mask; another
// frame must change it; the page reports its frame rate. Skips without
// Chromium (Debian package chromium).

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <regex>

#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/tools/gaussian_spz.h"
#include "serve_process.h"
#include "tiny_run.h"

// Last: through <resolv.h> it defines _res, a name Eigen's headers use.
#include <httplib.h>

namespace tega::serve {
namespace {

namespace fs = std::filesystem;

std::string chromium() {
  for (const char* name : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(name)) return name;
  return "";
}

std::string run_command(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return output;
  std::array<char, 65536> buffer;
  size_t read;
  while ((read = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), read);
  pclose(pipe);
  return output;
}

std::string base64_decode(const std::string& text) {
  static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    const size_t value = alphabet.find(c);
    if (value == std::string::npos) continue;  // padding
    bits = (bits << 6) | static_cast<uint32_t>(value);
    if ((count += 6) >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xff));
    }
  }
  return out;
}

struct PageResult {
  std::string state, error;
  Image8 image;
  double render_fps = 0;
};

std::string element_text(const std::string& dom, const std::string& id) {
  std::smatch match;
  if (std::regex_search(dom, match, std::regex("id=\"" + id + "\"[^>]*>([^<]*)<"))) return match[1];
  return "";
}

// `asynchronous`: the page finishes after its load event (an SPZ file is unpacked by the browser's
// DecompressionStream): Chromium's virtual time lets it before the DOM is read.
PageResult page(const std::string& browser, const test::ServeProcess& server, const fs::path& scratch,
                const std::string& query, bool asynchronous = false) {
  const std::string dom = run_command("timeout 180 " + browser +
                                      " --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
                                      " --user-data-dir=" + (scratch / "profile").string() +
                                      (asynchronous ? " --virtual-time-budget=30000" : "") + " --dump-dom '" +
                                      server.url() + "/?" + query + "' 2>/dev/null");
  PageResult result;
  std::smatch state;
  if (std::regex_search(dom, state, std::regex("<body[^>]*data-state=\"([a-z]+)\""))) result.state = state[1];
  result.error = element_text(dom, "error");
  const std::string png = element_text(dom, "still-png");
  const std::string prefix = "data:image/png;base64,";
  if (png.rfind(prefix, 0) == 0) {
    test::write_text(scratch / "page.png", base64_decode(png.substr(prefix.size())));
    result.image = read_image_u8(scratch / "page.png");
  }
  try {
    result.render_fps = std::stod(element_text(dom, "render-fps"));
  } catch (const std::exception&) {
  }
  return result;
}

// PSNR over the pixels whose dataset alpha exceeds 0.5 (tega eval's head mask).
double masked_psnr(const Image8& a, const Image8& b, const Image8& matte) {
  double squared = 0;
  int64_t count = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (matte.at(x, y, 3) <= 127) continue;
      for (int ch = 0; ch < 3; ++ch) {
        const double d = (a.at(x, y, ch) - b.at(x, y, ch)) / 255.0;
        squared += d * d;
      }
      ++count;
    }
  return 10 * std::log10(1.0 / (squared / (3.0 * count)));
}

TEST(Page, RendersADatasetFrameAsTegaRenderDoesAndScrubsToAnother) {
  const std::string browser = chromium();
  if (browser.empty()) GTEST_SKIP() << "no chromium (Debian package chromium): the page is not tested";
  test::TinyRun tiny;
  const fs::path renders = tiny.tmp / "renders";
  ASSERT_EQ(std::system((std::string(TEGA_EXECUTABLE) + " -q render --model " + tiny.run.string() + " --out " +
                         renders.string() + " --cameras cam00 --frames smile_000000,blink_000000 --no-video "
                         "--no-side-by-side --device cpu")
                            .c_str()),
            0);
  test::ServeProcess server(tiny.run);
  // Ready once the index answers: frames are posed on request.
  httplib::Client client("127.0.0.1", server.port);
  for (int attempt = 0; attempt < 600 && !client.Get("/api/runs"); ++attempt)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));

  const Image8 matte = read_image_u8(tiny.dataset.image_path("cam00", "smile_000000"));
  const PageResult smile = page(browser, server, tiny.tmp.path(), "still=1&frame=smile_000000&camera=cam00");
  ASSERT_EQ(smile.state, "done") << smile.error;
  ASSERT_EQ(smile.image.width, test::TinyRun::kWidth);
  ASSERT_EQ(smile.image.height, test::TinyRun::kHeight);
  const Image8 rendered = read_image_u8(renders / "cam00" / "smile_000000.png");
  const double psnr = masked_psnr(smile.image, rendered, matte);
  std::cout << "page vs tega render, inside the mask: " << psnr << " dB; page renders at " << smile.render_fps
            << " fps\n";
  EXPECT_GE(psnr, 30.0);
  EXPECT_GT(smile.render_fps, 0.0);

  const PageResult blink = page(browser, server, tiny.tmp.path(), "still=1&frame=blink_000000&camera=cam00");
  ASSERT_EQ(blink.state, "done") << blink.error;
  EXPECT_GE(masked_psnr(blink.image, read_image_u8(renders / "cam00" / "blink_000000.png"), matte), 30.0);
  EXPECT_LT(masked_psnr(blink.image, smile.image, matte), 30.0) << "another frame must change the image";

  const PageResult unknown = page(browser, server, tiny.tmp.path(), "still=1&frame=nosuch&camera=cam00");
  EXPECT_EQ(unknown.state, "error");
  EXPECT_NE(unknown.error.find("no frame nosuch"), std::string::npos) << unknown.error;
}

// `tega export --format spz` read by the page: its render of the file from a dataset camera
// against tega's reading of the same file, rendered by tega's rasterizer.
TEST(Page, LoadsAnExportedSpzFile) {
  const std::string browser = chromium();
  if (browser.empty()) GTEST_SKIP() << "no chromium (Debian package chromium): the page is not tested";
  test::TinyRun tiny;
  const fs::path spz = tiny.tmp / "smile.spz";
  ASSERT_EQ(std::system((std::string(TEGA_EXECUTABLE) + " -q export --model " + tiny.run.string() +
                         " --frame smile_000000 --device cpu --out " + spz.string())
                            .c_str()),
            0);
  test::ServeProcess server(tiny.run, {"--splat", spz.string()});
  httplib::Client client("127.0.0.1", server.port);
  for (int attempt = 0; attempt < 600 && !client.Get("/api/splats"); ++attempt)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(client.Get("/api/splats/nosuch.spz")->status, 404);

  const PageResult shown = page(browser, server, tiny.tmp.path(), "still=1&splat=smile.spz&camera=cam00", true);
  ASSERT_EQ(shown.state, "done") << shown.error;
  ASSERT_EQ(shown.image.width, test::TinyRun::kWidth);

  const Camera& camera = tiny.dataset.rig.camera("cam00");
  const tools::SpzCloud cloud = tools::read_gaussian_spz(spz);
  const at::Tensor background = at::tensor(tiny.avatar->options.background).to(at::kFloat);  // the page's, the run's
  const at::Tensor rgb = tools::render_cloud(cloud.gaussians, camera, background, cloud.antialiased);
  Image8 expected(camera.width, camera.height, 3);
  const at::Tensor bytes = (rgb.clamp(0, 1) * 255).round().to(at::kByte).permute({1, 2, 0}).contiguous();
  std::memcpy(expected.pixels.data(), bytes.data_ptr<uint8_t>(), expected.pixels.size());
  const Image8 matte = read_image_u8(tiny.dataset.image_path("cam00", "smile_000000"));
  const double psnr = masked_psnr(shown.image, expected, matte);
  std::cout << "page's SPZ render vs tega's of the same file, inside the mask: " << psnr << " dB\n";
  EXPECT_GE(psnr, 35.0);
}

}  // namespace
}  // namespace tega::serve
