#include "tega/core/options.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <sstream>

#include "tega/core/error.h"

namespace tega::detail {
namespace {

std::string known_keys(const std::vector<OptionField>& fields) {
  std::string keys;
  for (const auto& f : fields) keys += (keys.empty() ? "" : ", ") + f.key;
  return keys;
}

std::string location(const YAML::Node& node) {
  const auto mark = node.Mark();
  return mark.is_null() ? "" : " (line " + std::to_string(mark.line + 1) + ")";
}

template <class T>
T convert(const YAML::Node& node, const std::string& source, const std::string& key, const char* type) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(source, "option '" + key + "'" + location(node) + " must be " + type);
  }
}

void apply_node(std::vector<OptionField>& fields, const YAML::Node& map, const std::string& prefix,
                const std::string& source);

void assign(OptionField& field, const YAML::Node& value, const std::string& key, const std::string& source) {
  std::visit(
      [&](auto& target) {
        using T = std::decay_t<decltype(target)>;
        if constexpr (std::is_same_v<T, OptionField::Nested>) {
          if (!value.IsMap()) throw Error(source, "option '" + key + "'" + location(value) + " must be a mapping");
          apply_node(target, value, key + ".", source);
        } else if constexpr (std::is_same_v<T, OptionField::List>) {
          if (!value.IsSequence() && !value.IsNull()) {
            throw Error(source, "option '" + key + "'" + location(value) + " must be a list of mappings");
          }
          target.resize(0);  // elements the YAML lists start from their defaults, not the old list's
          target.resize(value.IsNull() ? 0 : value.size());
          for (size_t i = 0; i < target.size(); ++i) {
            const std::string element_key = key + "[" + std::to_string(i) + "]";
            if (!value[i].IsMap() && !value[i].IsNull()) {
              throw Error(source, "option '" + element_key + "'" + location(value[i]) + " must be a mapping");
            }
            if (value[i].IsNull()) continue;
            OptionField::Nested element = target.element(i);
            apply_node(element, value[i], element_key + ".", source);
          }
        } else if constexpr (std::is_same_v<T, bool*>) {
          *target = convert<bool>(value, source, key, "true or false");
        } else if constexpr (std::is_same_v<T, int*>) {
          *target = convert<int>(value, source, key, "an integer");
        } else if constexpr (std::is_same_v<T, int64_t*>) {
          *target = convert<int64_t>(value, source, key, "an integer");
        } else if constexpr (std::is_same_v<T, float*>) {
          *target = convert<float>(value, source, key, "a number");
        } else if constexpr (std::is_same_v<T, double*>) {
          *target = convert<double>(value, source, key, "a number");
        } else if constexpr (std::is_same_v<T, std::string*>) {
          if (!value.IsScalar()) throw Error(source, "option '" + key + "'" + location(value) + " must be a string");
          *target = value.as<std::string>();
        } else if constexpr (std::is_same_v<T, std::vector<int>*>) {
          *target = convert<std::vector<int>>(value, source, key, "a list of integers");
        } else if constexpr (std::is_same_v<T, std::vector<double>*>) {
          *target = convert<std::vector<double>>(value, source, key, "a list of numbers");
        } else {
          *target = convert<std::vector<std::string>>(value, source, key, "a list of strings");
        }
      },
      field.target);
}

void apply_node(std::vector<OptionField>& fields, const YAML::Node& map, const std::string& prefix,
                const std::string& source) {
  for (const auto& entry : map) {
    if (!entry.first.IsScalar()) {
      const std::string within = prefix.empty() ? "" : " in '" + prefix.substr(0, prefix.size() - 1) + "'";
      throw Error(source, "an option name" + location(entry.first) + within +
                              " is a list or mapping; option names are plain words");
    }
    const auto key = entry.first.as<std::string>();
    auto it = std::find_if(fields.begin(), fields.end(), [&](const OptionField& f) { return f.key == key; });
    if (it == fields.end()) {
      throw Error(source, "unknown option '" + prefix + key + "'" + location(entry.first) +
                              "; known options" + (prefix.empty() ? "" : " of '" + prefix.substr(0, prefix.size() - 1) + "'") +
                              ": " + known_keys(fields));
    }
    assign(*it, entry.second, prefix + key, source);
  }
}

YAML::Node parse(const std::string& yaml, const std::string& source) {
  try {
    return YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw Error(source, "is not valid YAML: " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
}

void write_value(std::ostringstream& out, const OptionField::Target& target) {
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  std::visit(
      [&](const auto& value) {
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, std::string*>) {
          e << YAML::DoubleQuoted << *value;
        } else if constexpr (!std::is_same_v<T, OptionField::Nested> && !std::is_same_v<T, OptionField::List>) {
          e << *value;
        }
      },
      target);
  out << e.c_str();
}

void write_fields(std::ostringstream& out, const std::vector<OptionField>& fields, int indent) {
  const std::string pad(indent, ' ');
  for (const auto& f : fields) {
    std::istringstream doc(f.doc);
    for (std::string line; std::getline(doc, line);) out << pad << "# " << line << "\n";
    if (const auto* nested = std::get_if<OptionField::Nested>(&f.target)) {
      out << pad << f.key << ":\n";
      write_fields(out, *nested, indent + 2);
    } else if (const auto* list = std::get_if<OptionField::List>(&f.target)) {
      if (list->size() == 0) {
        out << pad << f.key << ": []\n";
        continue;
      }
      out << pad << f.key << ":\n";
      for (size_t i = 0; i < list->size(); ++i) {
        out << pad << "  -\n";
        write_fields(out, list->element(i), indent + 4);
      }
    } else {
      out << pad << f.key << ": ";
      write_value(out, f.target);
      out << "\n";
    }
  }
}

}  // namespace

void apply_yaml_text(std::vector<OptionField>& fields, const std::string& yaml, const std::string& section,
                     const std::string& source) {
  YAML::Node node = parse(yaml, source);
  std::string prefix;
  std::istringstream path(section);
  for (std::string part; std::getline(path, part, '.');) {
    if (!node.IsMap() || !node[part]) return;  // section absent: defaults stand
    node = node[part];
    prefix += part + ".";
  }
  if (node.IsNull()) return;
  if (!node.IsMap()) {
    throw Error(source, (section.empty() ? std::string("the document") : "section '" + section + "'") +
                            " must be a mapping of option names to values");
  }
  apply_node(fields, node, prefix.empty() ? "" : prefix, source);
}

std::string fields_to_yaml(const std::vector<OptionField>& fields) {
  std::ostringstream out;
  write_fields(out, fields, 0);
  return out.str();
}

void set_field(std::vector<OptionField>& fields, const std::string& dotted_key, const std::string& value,
               const std::string& source) {
  // Build the nested mapping {a: {b: value}} and apply it like a file.
  std::string yaml;
  std::string indent;
  std::istringstream path(dotted_key);
  std::vector<std::string> parts;
  for (std::string part; std::getline(path, part, '.');) parts.push_back(part);
  if (parts.empty()) throw Error(source, "empty option name");
  for (size_t i = 0; i < parts.size(); ++i) {
    yaml += indent + parts[i] + ":" + (i + 1 < parts.size() ? "\n" : " " + value + "\n");
    indent += "  ";
  }
  apply_yaml_text(fields, yaml, "", source);
}

}  // namespace tega::detail
