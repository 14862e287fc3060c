#pragma once
// Stage options from YAML. Every stage has a `struct Options` whose fields
// carry their defaults and document themselves through one visit() method:
//
//   struct Options {
//     int cameras = 13;
//     template <class V> void visit(V& v) { v("cameras", cameras, "Number of cameras."); }
//   };
//
// A field may itself be a struct with visit() (a nested YAML mapping), or a
// std::vector of such structs (a YAML sequence of mappings, e.g. a rig's
// cameras); a list given in YAML replaces the default list whole.
// Loading is strict: a key that is not a field is an error naming the file,
// the key and the known keys; so is a value of the wrong type.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "tega/core/files.h"

namespace tega {

struct OptionField {
  using Nested = std::vector<OptionField>;
  // A std::vector of option structs, reached through the vector it belongs to.
  struct List {
    std::function<size_t()> size;
    std::function<void(size_t)> resize;
    std::function<Nested(size_t)> element;  // the fields of element i
  };
  using Target = std::variant<bool*, int*, int64_t*, float*, double*, std::string*, std::vector<int>*,
                              std::vector<double>*, std::vector<std::string>*, Nested, List>;
  std::string key;
  std::string doc;
  Target target;
};

class OptionCollector;

template <class T>
concept OptionStruct = requires(T& value, OptionCollector& collector) { value.visit(collector); };

template <class T>
struct is_option_struct_list : std::false_type {};
template <OptionStruct T>
struct is_option_struct_list<std::vector<T>> : std::true_type {};

class OptionCollector {
 public:
  template <class T>
  void operator()(const char* key, T& value, const char* doc) {
    if constexpr (OptionStruct<T>) {
      OptionCollector nested;
      value.visit(nested);
      fields.push_back({key, doc, std::move(nested.fields)});
    } else if constexpr (is_option_struct_list<T>::value) {
      OptionField::List list{[&value] { return value.size(); }, [&value](size_t n) { value.resize(n); },
                             [&value](size_t i) {
                               OptionCollector element;
                               value[i].visit(element);
                               return std::move(element.fields);
                             }};
      fields.push_back({key, doc, std::move(list)});
    } else {
      fields.push_back({key, doc, &value});
    }
  }
  std::vector<OptionField> fields;
};

namespace detail {
void apply_yaml_text(std::vector<OptionField>& fields, const std::string& yaml, const std::string& section,
                     const std::string& source);
std::string fields_to_yaml(const std::vector<OptionField>& fields);
void set_field(std::vector<OptionField>& fields, const std::string& dotted_key, const std::string& value,
               const std::string& source);
}  // namespace detail

// Applies the mapping at `section` (dotted path, "" = whole document) of a YAML
// file onto `options`; keys it does not set keep their defaults. A missing
// section leaves everything at its default.
template <class Options>
void load_options(Options& options, const std::filesystem::path& file, const std::string& section = "");

// Same, from YAML text; `source` names it in errors.
template <class Options>
void load_options_from_string(Options& options, const std::string& yaml, const std::string& section,
                              const std::string& source) {
  OptionCollector c;
  options.visit(c);
  detail::apply_yaml_text(c.fields, yaml, section, source);
}


template <class Options>
void load_options(Options& options, const std::filesystem::path& file, const std::string& section) {
  load_options_from_string(options, read_text_file(file), section, file.string());
}

// `key=value` override (dotted keys reach nested options); value is YAML.
template <class Options>
void set_option(Options& options, const std::string& dotted_key, const std::string& value) {
  OptionCollector c;
  options.visit(c);
  detail::set_field(c.fields, dotted_key, value, "--set " + dotted_key);
}

// The options as YAML, every field preceded by its documentation as a comment.
template <class Options>
std::string options_to_yaml(const Options& options) {
  Options copy = options;
  OptionCollector c;
  copy.visit(c);
  return detail::fields_to_yaml(c.fields);
}

}  // namespace tega
