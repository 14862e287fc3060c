#include "fuzz_target.h"
#include "tega/capture/options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/synth/options.h"

namespace {

// Loads section `section` of the YAML into stage options, then checks that the
// options it printed load again: --print-options output is a valid config.
template <class Options>
void load_and_reprint(const std::string& yaml, const std::string& section) {
  Options options;
  tega::load_options_from_string(options, yaml, section, "fuzzed.yaml");
  const std::string printed = tega::options_to_yaml(options);
  Options reloaded;
  try {
    tega::load_options_from_string(reloaded, printed, "", "printed.yaml");
  } catch (const tega::Error& error) {
    throw std::logic_error(std::string("options printed by options_to_yaml do not load: ") + error.what());
  }
}

}  // namespace

// Stage options: the virtual studio's (nested structs, lists of numbers and
// strings) under `synth:` and the capture rig config's (a list of mappings)
// under `capture:`, each loaded even when the other fails.
TEGA_FUZZ_TARGET(options_yaml) {
  const std::string yaml(reinterpret_cast<const char*>(data), size);
  try {
    load_and_reprint<tega::synth::Options>(yaml, "synth");
  } catch (const tega::Error&) {
  }
  load_and_reprint<tega::capture::RigConfig>(yaml, "capture");
}
