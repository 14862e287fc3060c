#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "tega/core/error.h"
#include "tega/synth/performance.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

struct Event {
  std::vector<std::string> names;
  float amplitude;
  double start, rise, hold, fall;

  double envelope(double t) const {
    const double up = smoothstep(start, start + rise, t);
    const double down = 1.0 - smoothstep(start + rise + hold, start + rise + hold + fall, t);
    return amplitude * std::min(up, down);
  }
};

const std::vector<std::string> kChannels = {"eyeBlink_L",    "eyeBlink_R",    "jawOpen",
                                            "browInnerUp_L", "browInnerUp_R", "browOuterUp_L",
                                            "browOuterUp_R", "mouthSmile_L",  "mouthSmile_R"};
const std::vector<std::string> kBrows = {"browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R"};
const std::vector<std::string> kBlink = {"eyeBlink_L", "eyeBlink_R"};
const std::vector<std::string> kSmile = {"mouthSmile_L", "mouthSmile_R"};

Event blink(double start) { return {kBlink, 1.0f, start, 0.05, 0.06, 0.05}; }

std::vector<Event> script_events(const std::string& name) {
  if (name == "expressions")
    return {{kBrows, 1.0f, 0.04, 0.08, 0.15, 0.08}, blink(0.2),
            {kSmile, 0.9f, 0.36, 0.08, 0.12, 0.08},  {{"jawOpen"}, 0.9f, 0.6, 0.08, 0.14, 0.08},
            blink(0.82)};
  if (name == "speech") {
    std::vector<Event> e = {{kSmile, 0.4f, 0.3, 0.1, 0.3, 0.1},
                            {{"browInnerUp_L", "browInnerUp_R"}, 0.6f, 0.55, 0.05, 0.08, 0.06},
                            blink(0.42)};
    const double starts[] = {0.04, 0.2, 0.38, 0.56, 0.74};
    const float amplitudes[] = {0.5f, 0.3f, 0.6f, 0.4f, 0.55f};
    for (int i = 0; i < 5; ++i) e.push_back({{"jawOpen"}, amplitudes[i], starts[i], 0.05, 0.03, 0.06});
    return e;
  }
  if (name == "freestyle")
    return {{{"browOuterUp_L", "browOuterUp_R", "jawOpen"}, 0.8f, 0.06, 0.08, 0.15, 0.08},
            {{"mouthSmile_L"}, 0.9f, 0.42, 0.08, 0.14, 0.08},
            {{"eyeBlink_R"}, 1.0f, 0.48, 0.05, 0.08, 0.05},
            {{"browInnerUp_L", "browInnerUp_R"}, 0.7f, 0.68, 0.06, 0.1, 0.06},
            blink(0.84)};
  throw Error("unknown performance script '" + name + "' (known: expressions, speech, freestyle)");
}

Eigen::Matrix3d rotation(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

}  // namespace

std::vector<std::string> performance_script_names() { return {"expressions", "speech", "freestyle"}; }

bool is_performance_script(const std::string& name) {
  const auto names = performance_script_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::vector<PerformanceFrame> perform(const std::string& script, int frames, uint64_t seed) {
  if (frames < 1) throw Error("a performance take needs at least 1 frame");
  const std::vector<Event> events = script_events(script);

  // Head motion: a few slow sinusoids whose amplitudes and phases depend on
  // the seed and the script, so that every take moves differently.
  const uint64_t motion_seed = hash_of(seed, hash_string(script.c_str()));
  const auto wave = [&](int channel, double amplitude, double t) {
    const double cycles = 0.6 + 0.8 * uniform(motion_seed, channel, 0);
    const double phase = 2 * std::numbers::pi * uniform(motion_seed, channel, 1);
    const double scale = 0.6 + 0.4 * uniform(motion_seed, channel, 2);
    return scale * amplitude * std::sin(2 * std::numbers::pi * cycles * t + phase);
  };
  constexpr double kDeg = std::numbers::pi / 180.0;

  std::vector<PerformanceFrame> out(frames);
  for (int i = 0; i < frames; ++i) {
    PerformanceFrame& f = out[i];
    f.time = frames == 1 ? 0.0 : double(i) / (frames - 1);
    std::map<std::string, double> sum;
    for (const Event& e : events)
      for (const auto& n : e.names) sum[n] += e.envelope(f.time);
    for (const auto& channel : kChannels)
      f.expression.emplace_back(channel, float(std::clamp(sum[channel], 0.0, 1.0)));
    f.motion.R = rotation(wave(0, 14 * kDeg, f.time), wave(1, 7 * kDeg, f.time), wave(2, 4 * kDeg, f.time));
    f.motion.t = Eigen::Vector3d(wave(3, 0.01, f.time), wave(4, 0.008, f.time), wave(5, 0.01, f.time));
  }
  return out;
}

}  // namespace tega::synth
