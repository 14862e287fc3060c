#include "tega/serve/server.h"

#include <chrono>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "frame_cache.h"
#include "run_index.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/interrupt.h"
#include "tega/core/log.h"
#include "tega/serve/posed_frame.h"
#include "tega/serve/run_catalog.h"
#include "tega/serve/safe_path.h"
#include "tega/tools/gaussian_spz.h"
#include "tega/tools/load_run.h"
#include "tega/tools/render_avatar.h"
#include "web_assets.h"

// Last: through <resolv.h> it defines _res, a name Eigen's headers use.
#include <httplib.h>

namespace tega::serve {

namespace fs = std::filesystem;

namespace {

struct ServedRun {
  RunLocation location;
  tools::LoadedRun loaded;
  std::string static_bytes;
  std::string index_json;
  std::map<std::string, size_t> frames;  // id -> index in the dataset's frames
  std::map<std::string, fs::path> mesh_frames;  // id -> a --meshes file
  std::timed_mutex posing;               // the model poses one frame at a time
};

void answer_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", message}}.dump(), "application/json");
}

// Byte ranges are httplib's to cut; one beyond the body is answered here,
// since this httplib would send a malformed 206 for it.
bool ranges_fit(const httplib::Request& req, httplib::Response& res, size_t size) {
  for (const auto& [first, last] : req.ranges) {
    const bool suffix = first < 0;
    if ((suffix && (last <= 0)) || (!suffix && (static_cast<size_t>(first) >= size || (last >= 0 && last < first)))) {
      answer_error(res, 416, "range outside the " + std::to_string(size) + " bytes");
      res.set_header("Content-Range", "bytes */" + std::to_string(size));
      return false;
    }
  }
  return true;
}

void answer_bytes(const httplib::Request& req, httplib::Response& res, std::string bytes, const char* type) {
  if (!ranges_fit(req, res, bytes.size())) return;
  res.set_content(std::move(bytes), type);
}

// A dataset image as PNG bytes: PNG files as they are, other formats (raw
// pixels in zstd) decoded and written as PNG through a temporary file.
std::string png_bytes(const fs::path& image) {
  if (image.extension() == ".png") return read_text_file(image);
  const fs::path temporary =
      fs::temp_directory_path() / ("tega-serve-" + std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id())) + ".png");
  write_image(read_image_u8(image), temporary);
  std::string bytes = read_text_file(temporary);
  fs::remove(temporary);
  return bytes;
}

}  // namespace

struct Server::Impl {
  Options options;
  std::vector<std::unique_ptr<ServedRun>> runs;
  std::string runs_json;
  std::map<std::string, std::string> splats;  // file name -> the SPZ file's bytes
  std::string splats_json;
  FrameCache cache;
  httplib::Server http;
  std::thread listener;
  int port = 0;

  explicit Impl(const Options& o) : options(o), cache(o.cache_bytes) {
    nlohmann::json listing = nlohmann::json::array();
    for (RunLocation& location : find_runs(options.target)) {
      auto run = std::make_unique<ServedRun>();
      run->loaded = tools::load_run(location.run, "", options.device);
      const StaticPart part = static_part(*run->loaded.avatar);
      run->static_bytes = encode_static(part);
      const Dataset& dataset = run->loaded.dataset;
      for (size_t i = 0; i < dataset.frames.size(); ++i) run->frames[dataset.frames[i].id] = i;
      std::vector<MeshTake> mesh_takes;
      for (const fs::path& directory : options.meshes) {
        MeshTake take{fs::absolute(directory).lexically_normal().filename().string(), {}};
        if (take.name.empty()) take.name = fs::absolute(directory).lexically_normal().parent_path().filename().string();
        for (const fs::path& file : tools::mesh_files(directory)) {
          const std::string id = take.name + "." + file.stem().string();
          if (run->frames.count(id) || !run->mesh_frames.emplace(id, file).second)
            throw Error(file, "would be frame " + id + ", a name another frame has: give the directories other names");
          take.frames.push_back(id);
        }
        mesh_takes.push_back(std::move(take));
      }
      run->index_json = run_index(location.id, dataset, part, options.fps, location.eval_json, mesh_takes).dump();
      listing.push_back({{"id", location.id}, {"run", location.run.string()}, {"dataset", dataset.root.string()},
                         {"gaussians", part.size()}, {"index", "/api/runs/" + location.id + "/index.json"}});
      run->location = std::move(location);
      runs.push_back(std::move(run));
    }
    runs_json = nlohmann::json{{"runs", listing}}.dump();
    nlohmann::json splat_listing = nlohmann::json::array();
    for (const fs::path& file : options.splats) {
      const tools::SpzCloud cloud = tools::read_gaussian_spz(file);  // names the file when it is no SPZ
      const std::string name = file.filename().string();
      if (!splats.emplace(name, read_text_file(file)).second)
        throw Error(file, "has the name of another --splat file; the page opens them by name");
      splat_listing.push_back({{"name", name}, {"url", "/api/splats/" + name}, {"gaussians", cloud.gaussians.size()}});
    }
    splats_json = nlohmann::json{{"splats", splat_listing}}.dump();
    routes();
  }

  ServedRun* find_run(const std::string& id) {
    for (auto& run : runs)
      if (run->location.id == id) return run.get();
    return nullptr;
  }

  void routes() {
    http.new_task_queue = [threads = options.threads] { return new httplib::ThreadPool(threads); };
    http.Get("/", [](const httplib::Request&, httplib::Response& res) { answer_asset(res, "index.html"); });
    http.Get(R"(/app/([^/]+))", [](const httplib::Request& req, httplib::Response& res) {
      answer_asset(res, req.matches[1].str());
    });
    http.Get("/api/runs", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(runs_json, "application/json");
    });
    http.Get("/api/splats", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(splats_json, "application/json");
    });
    http.Get(R"(/api/splats/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
      const auto splat = splats.find(req.matches[1].str());
      if (splat == splats.end()) return answer_error(res, 404, "no splat file '" + req.matches[1].str() + "' is served");
      answer_bytes(req, res, splat->second, "application/octet-stream");
    });
    http.Get(R"(/api/runs/([^/]+)/index\.json)", [this](const httplib::Request& req, httplib::Response& res) {
      if (ServedRun* run = run_or_404(req, res)) res.set_content(run->index_json, "application/json");
    });
    http.Get(R"(/api/runs/([^/]+)/static\.bin)", [this](const httplib::Request& req, httplib::Response& res) {
      if (ServedRun* run = run_or_404(req, res)) answer_bytes(req, res, run->static_bytes, "application/octet-stream");
    });
    http.Get(R"(/api/runs/([^/]+)/frames/([^/]+)\.bin)", [this](const httplib::Request& req, httplib::Response& res) {
      if (ServedRun* run = run_or_404(req, res)) answer_frame(*run, req, res);
    });
    http.Get(R"(/api/runs/([^/]+)/images/([^/]+)/([^/]+)\.png)",
             [this](const httplib::Request& req, httplib::Response& res) {
               if (ServedRun* run = run_or_404(req, res)) answer_image(*run, req, res);
             });
    http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
      if (res.body.empty()) answer_error(res, res.status, "nothing is served at " + req.path);
    });
    http.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr error) {
      std::string message = "unknown error";
      try {
        std::rethrow_exception(error);
      } catch (const std::exception& e) {
        message = e.what();
      }
      logging::warn("tega serve: %s: %s", req.path.c_str(), message.c_str());
      answer_error(res, 500, message);
    });
  }

  static void answer_asset(httplib::Response& res, const std::string& name) {
    for (const WebAsset& asset : web_assets())
      if (asset.name == name) {
        res.set_content(std::string(asset.bytes), std::string(asset.content_type));
        return;
      }
    answer_error(res, 404, "the page has no file " + name);
  }

  ServedRun* run_or_404(const httplib::Request& req, httplib::Response& res) {
    ServedRun* run = find_run(req.matches[1].str());
    if (!run) answer_error(res, 404, "no run named " + req.matches[1].str());
    return run;
  }

  void answer_frame(ServedRun& run, const httplib::Request& req, httplib::Response& res) {
    const std::string id = req.matches[2].str();
    const auto frame = run.frames.find(id);
    const auto mesh = run.mesh_frames.find(id);
    if (frame == run.frames.end() && mesh == run.mesh_frames.end())
      return answer_error(res, 404, "run " + run.location.id + " has no frame " + id);
    const std::string key = run.location.id + "/" + id;
    std::shared_ptr<const std::string> bytes = cache.find(key);
    if (!bytes) {
      std::unique_lock lock(run.posing, std::defer_lock);
      if (!lock.try_lock_for(std::chrono::duration<double>(options.pose_wait_seconds))) {
        res.set_header("Retry-After", "1");
        return answer_error(res, 503, "run " + run.location.id + " is busy posing other frames: try again");
      }
      bytes = cache.find(key);  // posed while this request waited
      if (!bytes) {
        const Dataset& dataset = run.loaded.dataset;
        // Mesh files in the head pose of the first training frame, as `tega render --meshes` poses them.
        const tools::RenderFrame posed =
            frame != run.frames.end()
                ? tools::dataset_frames(dataset, {dataset.frames[frame->second].id}).front()
                : tools::mesh_frame(mesh->second, dataset.template_mesh.num_vertices(),
                                    dataset.frame(dataset.train.frames.front()).head_to_world, /*head_space=*/false);
        bytes = std::make_shared<const std::string>(encode_frame(posed_frame(*run.loaded.avatar, posed)));
        cache.insert(key, bytes);
      }
    }
    answer_bytes(req, res, *bytes, "application/octet-stream");
  }

  void answer_image(ServedRun& run, const httplib::Request& req, httplib::Response& res) {
    const Dataset& dataset = run.loaded.dataset;
    const std::string camera = req.matches[2].str(), frame = req.matches[3].str();
    if (!dataset.rig.contains(camera)) return answer_error(res, 404, "the dataset has no camera " + camera);
    if (!run.frames.count(frame)) return answer_error(res, 404, "the dataset has no frame " + frame);
    if (!dataset.has_image(camera, frame))
      return answer_error(res, 404, "the dataset records the image of " + camera + ", " + frame + " as missing");
    const fs::path relative = dataset.image_path(camera, frame).lexically_relative(dataset.root);
    const std::optional<fs::path> file = resolve_inside(dataset.root, relative);
    if (!file) return answer_error(res, 404, "no image of " + camera + ", " + frame + " inside the dataset");
    answer_bytes(req, res, png_bytes(*file), "image/png");
  }
};

Server::Server(const Options& options) : impl_(std::make_unique<Impl>(options)) {}

Server::~Server() { stop(); }

void Server::start() {
  Impl& s = *impl_;
  s.port = s.options.port == 0 ? s.http.bind_to_any_port(s.options.host)
                               : (s.http.bind_to_port(s.options.host, s.options.port) ? s.options.port : -1);
  if (s.port < 0)
    throw Error("tega serve: cannot listen on " + s.options.host + ":" + std::to_string(s.options.port) +
                " (in use, or not an address of this machine)");
  s.listener = std::thread([&s] { s.http.listen_after_bind(); });
}

int Server::port() const { return impl_->port; }

void Server::stop() {
  impl_->http.stop();
  if (impl_->listener.joinable()) impl_->listener.join();
}

void serve(const Options& options) {
  const InterruptGuard interrupt;
  Server server(options);
  server.start();
  logging::info("tega serve: http://%s:%d/ (Ctrl-C stops)", options.host.c_str(), server.port());
  while (!InterruptGuard::requested()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  logging::info("tega serve: stopping");
  server.stop();
}

}  // namespace tega::serve
