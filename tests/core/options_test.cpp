#include "tega/core/options.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "test_support.h"

namespace {

struct ScheduleOptions {
  double start = 1.0;
  double end = 0.1;
  template <class V>
  void visit(V& v) {
    v("start", start, "Weight at iteration 0.");
    v("end", end, "Weight at the end.");
  }
};

struct ExampleOptions {
  int cameras = 13;
  bool antialias = true;
  std::string name = "studio";
  std::vector<double> background{0.1, 0.2, 0.3};
  ScheduleOptions smoothness;
  template <class V>
  void visit(V& v) {
    v("cameras", cameras, "Number of cameras.");
    v("antialias", antialias, "Supersample edges.");
    v("name", name, "Name of the take.");
    v("background", background, "Background colour, linear RGB.");
    v("smoothness", smoothness, "Smoothness weight schedule.");
  }
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const tega::Error& e) {
    return e.what();
  }
  return "";
}

TEST(Options, YamlOverridesOnlyTheKeysItNames) {
  ExampleOptions o;
  tega::load_options_from_string(o, "cameras: 6\nsmoothness: {end: 0.5}\n", "", "test.yaml");
  EXPECT_EQ(o.cameras, 6);
  EXPECT_DOUBLE_EQ(o.smoothness.end, 0.5);
  EXPECT_DOUBLE_EQ(o.smoothness.start, 1.0);
  EXPECT_EQ(o.name, "studio");
}

TEST(Options, SectionOfALargerDocument) {
  ExampleOptions o;
  tega::load_options_from_string(o, "stages:\n  synth:\n    name: demo\n  other: {x: 1}\n", "stages.synth",
                                 "pipeline.yaml");
  EXPECT_EQ(o.name, "demo");
  ExampleOptions untouched;
  tega::load_options_from_string(untouched, "other: 1\n", "stages.synth", "pipeline.yaml");
  EXPECT_EQ(untouched.cameras, 13);
}

TEST(Options, UnknownKeyIsAnErrorNamingFileKeyAndKnownKeys) {
  ExampleOptions o;
  const auto message = error_of([&] { tega::load_options_from_string(o, "cameraz: 4\n", "", "studio.yaml"); });
  EXPECT_NE(message.find("studio.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown option 'cameraz'"), std::string::npos) << message;
  EXPECT_NE(message.find("cameras"), std::string::npos) << message;

  const auto nested =
      error_of([&] { tega::load_options_from_string(o, "smoothness: {middle: 1}\n", "", "studio.yaml"); });
  EXPECT_NE(nested.find("'smoothness.middle'"), std::string::npos) << nested;

  // A name that is a list or a mapping (found by fuzzing: yaml-cpp's BadConversion escaped).
  const auto list_name = error_of([&] { tega::load_options_from_string(o, "[cameras]: 4\n", "", "studio.yaml"); });
  EXPECT_NE(list_name.find("studio.yaml: an option name (line 1) is a list or mapping"), std::string::npos)
      << list_name;
  const auto nested_name =
      error_of([&] { tega::load_options_from_string(o, "smoothness: {{a: 1}: 2}\n", "", "studio.yaml"); });
  EXPECT_NE(nested_name.find("in 'smoothness' is a list or mapping"), std::string::npos) << nested_name;
}

TEST(Options, WrongTypeIsAnErrorWithLine) {
  ExampleOptions o;
  const auto message =
      error_of([&] { tega::load_options_from_string(o, "name: x\ncameras: many\n", "", "studio.yaml"); });
  EXPECT_NE(message.find("'cameras' (line 2) must be an integer"), std::string::npos) << message;
  EXPECT_FALSE(error_of([&] { tega::load_options_from_string(o, "cameras: [1, 2\n", "", "bad.yaml"); }).empty());
}

TEST(Options, SetOptionReachesNestedFields) {
  ExampleOptions o;
  tega::set_option(o, "smoothness.start", "2.5");
  tega::set_option(o, "background", "[1, 1, 1]");
  EXPECT_DOUBLE_EQ(o.smoothness.start, 2.5);
  EXPECT_EQ(o.background, (std::vector<double>{1, 1, 1}));
  EXPECT_FALSE(error_of([&] { tega::set_option(o, "smoothness.nope", "1"); }).empty());
}

TEST(Options, PrintedYamlDocumentsEveryFieldAndLoadsBack) {
  ExampleOptions o;
  o.cameras = 7;
  o.smoothness.end = 0.25;
  const std::string yaml = tega::options_to_yaml(o);
  EXPECT_NE(yaml.find("# Number of cameras."), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("# Weight at the end."), std::string::npos) << yaml;
  ExampleOptions back;
  tega::load_options_from_string(back, yaml, "", "printed");
  EXPECT_EQ(back.cameras, 7);
  EXPECT_DOUBLE_EQ(back.smoothness.end, 0.25);
  EXPECT_EQ(back.background, o.background);
}

struct ShotOptions {
  std::string camera = "cam00";
  int frames = 1;
  template <class V>
  void visit(V& v) {
    v("camera", camera, "Camera name.");
    v("frames", frames, "Frames to take.");
  }
};

struct PlanOptions {
  std::vector<ShotOptions> shots{ShotOptions{}};
  template <class V>
  void visit(V& v) {
    v("shots", shots, "Shots, in order.");
  }
};

TEST(Options, ListOfMappingsReplacesTheDefaultAndKeepsElementDefaults) {
  PlanOptions o;
  tega::load_options_from_string(o, "shots:\n  - {camera: a, frames: 3}\n  - {camera: b}\n", "", "plan.yaml");
  ASSERT_EQ(o.shots.size(), 2u);
  EXPECT_EQ(o.shots[0].camera, "a");
  EXPECT_EQ(o.shots[0].frames, 3);
  EXPECT_EQ(o.shots[1].camera, "b");
  EXPECT_EQ(o.shots[1].frames, 1);

  const auto unknown = error_of([&] { tega::load_options_from_string(o, "shots: [{cam: a}]\n", "", "plan.yaml"); });
  EXPECT_NE(unknown.find("'shots[0].cam'"), std::string::npos) << unknown;
  const auto not_a_list = error_of([&] { tega::load_options_from_string(o, "shots: 3\n", "", "plan.yaml"); });
  EXPECT_NE(not_a_list.find("must be a list of mappings"), std::string::npos) << not_a_list;
}

TEST(Options, PrintedListLoadsBack) {
  PlanOptions o;
  o.shots = {{"left", 2}, {"right", 5}};
  const std::string yaml = tega::options_to_yaml(o);
  EXPECT_NE(yaml.find("# Frames to take."), std::string::npos) << yaml;
  PlanOptions back;
  back.shots.clear();
  tega::load_options_from_string(back, yaml, "", "printed");
  ASSERT_EQ(back.shots.size(), 2u);
  EXPECT_EQ(back.shots[1].camera, "right");
  EXPECT_EQ(back.shots[1].frames, 5);

  PlanOptions empty;
  empty.shots.clear();
  PlanOptions empty_back;
  tega::load_options_from_string(empty_back, tega::options_to_yaml(empty), "", "printed");
  EXPECT_TRUE(empty_back.shots.empty());
}

TEST(Options, MissingFileIsNamed) {
  ExampleOptions o;
  const auto message = error_of([&] { tega::load_options(o, "/nonexistent/dir/x.yaml"); });
  EXPECT_NE(message.find("/nonexistent/dir/x.yaml: does not exist"), std::string::npos) << message;
}

}  // namespace
