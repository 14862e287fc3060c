#include "stage_options.h"

namespace tega::cli {

void StageOptionFlags::add_to(CLI::App& command, const std::string& section_name, const std::string& what,
                              const std::string& set_example) {
  section = section_name;
  command.add_option("--config", config,
                     section.empty() ? "YAML file of " + what + " options (see --print-options)."
                                     : "YAML file whose `" + section + "` section sets options (see --print-options).");
  command.add_option("--set", overrides, "Override one option, e.g. --set " + set_example + " (repeatable).");
  command.add_flag("--print-options", print, "Print every " + what + " option with its default and exit.");
}

}  // namespace tega::cli
