// The server in-process on a free port, asked over HTTP with cpp-httplib's
// client: what it serves for a tiny trained run and a workspace, the 4xx
// answers (unknown names, paths outside the run, ranges beyond a body), the
// start-up errors for bad runs; and `tega serve` stopping on SIGTERM.

#include "tega/serve/server.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/serve/posed_frame.h"
#include "tega/serve/run_catalog.h"
#include "tega/serve/safe_path.h"
#include "tega/tools/load_run.h"
#include "serve_process.h"
#include "tiny_run.h"

// Last: through <resolv.h> it defines _res, a name Eigen's headers use.
#include <httplib.h>

namespace tega::serve {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Served : test::TinyRun {
  std::unique_ptr<Server> server;
  std::unique_ptr<httplib::Client> client;

  explicit Served(const fs::path& target = {}) {
    Options options;
    options.target = target.empty() ? run : target;
    options.port = 0;
    options.device = "cpu";
    server = std::make_unique<Server>(options);
    server->start();
    client = std::make_unique<httplib::Client>("127.0.0.1", server->port());
  }

  httplib::Result get(const std::string& path, const httplib::Headers& headers = {}) {
    return client->Get(path.c_str(), headers);
  }
};

// Callers wrap it in ASSERT_NO_FATAL_FAILURE: with no answer there is no body to read next.
void expect_status(const httplib::Result& result, int status, const std::string& path) {
  ASSERT_TRUE(result) << path << ": no answer (" << httplib::to_string(result.error()) << ")";
  EXPECT_EQ(result->status, status) << path << ": " << result->body;
}

TEST(Server, IndexListsCamerasTakesFramesFpsAndEvalNumbers) {
  test::TinyRun prepared;  // eval.json must exist before the server reads the run
  test::write_text(prepared.run / "eval.json", R"({"format": "tega-eval", "models": [{"name": "tiny", "iteration": 100,
      "splits": {"reenactment": {"views": 1, "metrics": {"psnr": {"mean": 31.5}}, "per_view": []}}}]})");
  Options options;
  options.target = prepared.run;
  options.port = 0;
  options.fps = 25;
  Server server(options);
  server.start();
  httplib::Client client("127.0.0.1", server.port());

  const auto runs = client.Get("/api/runs");
  ASSERT_TRUE(runs);
  EXPECT_EQ(json::parse(runs->body)["runs"][0]["id"], "run");
  const auto answer = client.Get("/api/runs/run/index.json");
  ASSERT_TRUE(answer);
  ASSERT_EQ(answer->status, 200);
  const json index = json::parse(answer->body);
  EXPECT_EQ(index["fps"], 25.0);
  EXPECT_EQ(index["gaussians"], 300);
  EXPECT_EQ(index["sh_degree"], 3);
  ASSERT_EQ(index["cameras"].size(), 2u);
  EXPECT_EQ(index["cameras"][0]["name"], "cam00");
  EXPECT_EQ(index["cameras"][0]["width"], test::TinyRun::kWidth);
  EXPECT_EQ(index["cameras"][0]["fx"], 80.0);
  EXPECT_EQ(index["cameras"][1]["split"], "test");
  const Eigen::Matrix3d& r = prepared.dataset.rig.cameras[1].world_to_camera.R;
  EXPECT_DOUBLE_EQ(index["cameras"][1]["rotation"][5].get<double>(), r(1, 2));
  ASSERT_EQ(index["takes"].size(), 2u);
  EXPECT_EQ(index["takes"][0]["name"], "smile");
  EXPECT_EQ(index["takes"][1]["frames"][0]["id"], "blink_000000");
  EXPECT_EQ(index["takes"][1]["frames"][0]["split"], "test");
  EXPECT_EQ(index["eval"]["models"][0]["splits"]["reenactment"]["metrics"]["psnr"]["mean"], 31.5);
  EXPECT_FALSE(index["eval"]["models"][0]["splits"]["reenactment"].contains("per_view"));
  EXPECT_EQ(index["urls"]["frame"], "/api/runs/run/frames/{frame}.bin");
}

TEST(Server, StaticPartAndFramesAreThePosedAvatarsStream) {
  Served s;
  tools::LoadedRun loaded = tools::load_run(s.run, "", "cpu");
  const auto fixed = s.get("/api/runs/run/static.bin");
  ASSERT_TRUE(fixed);
  EXPECT_EQ(fixed->status, 200);
  EXPECT_EQ(fixed->get_header_value("Content-Type"), "application/octet-stream");
  EXPECT_EQ(fixed->body, encode_static(static_part(*loaded.avatar)));
  for (const std::string id : {"smile_000000", "blink_000000", "smile_000000"}) {  // the last from the cache
    const auto frame = s.get("/api/runs/run/frames/" + id + ".bin");
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->status, 200);
    const tools::RenderFrame posed = tools::dataset_frames(loaded.dataset, {id}).front();
    EXPECT_EQ(frame->body, encode_frame(posed_frame(*loaded.avatar, posed))) << id;
  }
  EXPECT_NE(s.get("/api/runs/run/frames/smile_000000.bin")->body, s.get("/api/runs/run/frames/blink_000000.bin")->body);
}

// A directory of mesh files (a tracked take, a new performance) plays as a take of its own.
TEST(Server, MeshDirectoriesAreTakesOfTheirOwn) {
  test::TinyRun tiny;
  const fs::path take = tiny.tmp / "performance";
  fs::create_directories(take);
  fs::copy_file(tiny.dataset.mesh_path("blink_000000"), take / "000000.bin");
  fs::copy_file(tiny.dataset.mesh_path("smile_000000"), take / "000001.bin");
  Options options;
  options.target = tiny.run;
  options.port = 0;
  options.device = "cpu";
  options.meshes = {take};
  Server server(options);
  server.start();
  httplib::Client client("127.0.0.1", server.port());

  const auto index = client.Get("/api/runs/run/index.json");
  ASSERT_TRUE(index);
  const json takes = json::parse(index->body)["takes"];
  ASSERT_EQ(takes.back()["name"], "performance");
  EXPECT_EQ(takes.back()["frames"], json::parse(R"([{"id": "performance.000000", "split": "meshes"},
                                                     {"id": "performance.000001", "split": "meshes"}])"));

  tools::LoadedRun loaded = tools::load_run(tiny.run, "", "cpu");
  const Dataset& dataset = loaded.dataset;
  const RigidTransform pose = dataset.frame(dataset.train.frames.front()).head_to_world;
  for (const std::string stem : {"000000", "000001"}) {
    const auto frame = client.Get(("/api/runs/run/frames/performance." + stem + ".bin").c_str());
    ASSERT_TRUE(frame);
    ASSERT_EQ(frame->status, 200) << frame->body;
    const tools::RenderFrame posed =
        tools::mesh_frame(take / (stem + ".bin"), dataset.template_mesh.num_vertices(), pose, false);
    EXPECT_EQ(frame->body, encode_frame(posed_frame(*loaded.avatar, posed))) << stem;
  }
  EXPECT_NE(client.Get("/api/runs/run/frames/performance.000000.bin")->body,
            client.Get("/api/runs/run/frames/performance.000001.bin")->body);
  EXPECT_EQ(client.Get("/api/runs/run/frames/performance.000002.bin")->status, 404);
  EXPECT_EQ(client.Get("/api/runs/run/images/cam00/performance.000000.png")->status, 404);  // no captured image
}

TEST(Server, ImagesAreTheDatasetsFilesAndThePageIsServed) {
  Served s;
  const auto image = s.get("/api/runs/run/images/cam01/blink_000000.png");
  ASSERT_TRUE(image);
  EXPECT_EQ(image->status, 200);
  EXPECT_EQ(image->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(image->body, read_text_file(s.dataset.image_path("cam01", "blink_000000")));
  const auto page = s.get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<html"), std::string::npos);
}

TEST(Server, UnknownNamesAndPathsOutsideTheRunAre404AndItKeepsServing) {
  Served s;
  // A file outside the dataset that a link inside it points at.
  test::write_text(s.tmp / "secret.txt", "not for the browser");
  fs::remove(s.dataset.image_path("cam00", "blink_000000"));
  fs::create_symlink(s.tmp / "secret.txt", s.dataset.image_path("cam00", "blink_000000"));
  for (const std::string path :
       {"/api/runs/nosuch/index.json", "/api/runs/run/frames/nosuch.bin", "/api/runs/run/images/cam99/smile_000000.png",
        "/api/runs/run/images/cam00/nosuch.png", "/app/nosuch.js", "/nosuch", "/app/..%2F..%2F..%2Fetc%2Fpasswd",
        "/api/runs/run/images/cam00/..%2F..%2Fdataset.json.png", "/api/runs/..%2Frun/index.json",
        "/api/runs/run/frames/..%2F..%2Frun%2Frun.json.bin", "/api/runs/run/images/cam00/blink_000000.png"}) {
    const auto answer = s.get(path);
    ASSERT_NO_FATAL_FAILURE(expect_status(answer, 404, path));
    EXPECT_EQ(answer->body.find("not for the browser"), std::string::npos) << path;
    EXPECT_NO_THROW(json::parse(answer->body)["error"].get<std::string>()) << path << ": " << answer->body;
  }
  ASSERT_NO_FATAL_FAILURE(expect_status(s.get("/api/runs/run/index.json"), 200, "index after the 404s"));
}

TEST(Server, ByteRangesBeyondABodyAre416AndOthersArePartial) {
  Served s;
  const std::string path = "/api/runs/run/frames/smile_000000.bin";
  const std::string whole = s.get(path)->body;
  const auto partial = s.get(path, {httplib::make_range_header({{10, 19}})});
  ASSERT_NO_FATAL_FAILURE(expect_status(partial, 206, "bytes 10-19"));
  EXPECT_EQ(partial->body, whole.substr(10, 10));
  const auto beyond = s.get(path, {httplib::make_range_header({{int64_t(whole.size()) + 5, -1}})});
  ASSERT_NO_FATAL_FAILURE(expect_status(beyond, 416, "a range past the end"));
  EXPECT_EQ(beyond->get_header_value("Content-Range"), "bytes */" + std::to_string(whole.size()));
  expect_status(s.get("/api/runs/run/images/cam00/smile_000000.png", {httplib::make_range_header({{1 << 20, -1}})}),
                416, "an image range past the end");
  ASSERT_NO_FATAL_FAILURE(expect_status(s.get(path), 200, "the frame after the 416s"));
}

std::string error_of_starting(const fs::path& target) {
  Options options;
  options.target = target;
  options.port = 0;
  try {
    Server server(options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Server, ABadRunOrWorkspaceIsAnErrorNamingItAtStartUp) {
  test::TinyRun tiny;
  EXPECT_EQ(error_of_starting(tiny.tmp / "nosuch"), (tiny.tmp / "nosuch").string() + ": is not a directory: give a training run or a tega run workspace");
  EXPECT_NE(error_of_starting(tiny.tmp.path()).find(tiny.tmp.path().string() + ": holds no training run"), std::string::npos);
  fs::remove(tiny.run / "run.json");
  EXPECT_NE(error_of_starting(tiny.run).find((fs::canonical(tiny.run) / "run.json").string() + ": is missing"),
            std::string::npos);
}

TEST(Server, AWorkspaceServesEachSubjectsRun) {
  test::TinyRun tiny;
  const fs::path workspace = tiny.tmp / "workspace";
  fs::create_directories(workspace / "train" / "alice");
  fs::create_directories(workspace / "train" / ".staging-bob" / "run");  // unfinished: not served
  fs::rename(tiny.run, workspace / "train" / "alice" / "run");
  fs::create_directories(workspace / "eval" / "alice");
  test::write_text(workspace / "eval" / "alice" / "eval.json", json{{"models", json::array()}}.dump());
  Served s(workspace);
  const json runs = json::parse(s.get("/api/runs")->body)["runs"];
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0]["id"], "alice");
  const json index = json::parse(s.get("/api/runs/alice/index.json")->body);
  EXPECT_TRUE(index["eval"]["models"].is_array());
  ASSERT_NO_FATAL_FAILURE(expect_status(s.get("/api/runs/alice/frames/blink_000000.bin"), 200, "alice's frame"));
  ASSERT_NO_FATAL_FAILURE(expect_status(s.get("/api/runs/run/index.json"), 404, "the run by its directory name"));
}

TEST(SafePath, OnlyPathsThatResolveInsideTheRootPass) {
  test::TempDir tmp;
  fs::create_directories(tmp / "root" / "a");
  fs::create_directories(tmp / "root2");
  test::write_text(tmp / "root" / "a" / "file", "x");
  test::write_text(tmp / "root2" / "file", "y");
  fs::create_symlink(tmp / "root2" / "file", tmp / "root" / "a" / "out");
  fs::create_symlink(tmp / "root" / "a" / "file", tmp / "root" / "a" / "in");
  EXPECT_EQ(resolve_inside(tmp / "root", "a/file"), fs::canonical(tmp / "root" / "a" / "file"));
  EXPECT_EQ(resolve_inside(tmp / "root", "a/in"), fs::canonical(tmp / "root" / "a" / "file"));
  EXPECT_FALSE(resolve_inside(tmp / "root", "a/out"));
  EXPECT_FALSE(resolve_inside(tmp / "root", "a/../a/file"));
  EXPECT_FALSE(resolve_inside(tmp / "root", "../root2/file"));
  EXPECT_FALSE(resolve_inside(tmp / "root", (tmp / "root" / "a" / "file").string()));
  EXPECT_FALSE(resolve_inside(tmp / "root", "a/nosuch"));
}

TEST(TegaServe, AnswersThenStopsGracefullyOnSigterm) {
  test::TinyRun tiny;
  test::ServeProcess process(tiny.run);
  httplib::Client client("127.0.0.1", process.port);
  for (int attempt = 0; attempt < 600 && !client.Get("/api/runs"); ++attempt)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto answer = client.Get("/api/runs/run/frames/blink_000000.bin");
  ASSERT_TRUE(answer) << "tega serve did not answer within a minute";
  EXPECT_EQ(answer->status, 200);
  EXPECT_EQ(process.stop(), 0) << "tega serve did not exit with status 0 on SIGTERM";
  EXPECT_FALSE(client.Get("/api/runs")) << "still answering after SIGTERM";
}

}  // namespace
}  // namespace tega::serve
