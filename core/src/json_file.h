#pragma once
// JSON manifests core reads (dataset.json, take.json, capture.json, rig files).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <utility>

#include "tega/core/error.h"
#include "tega/core/json_file.h"

namespace tega::detail {

// Whether `value` is an integer that T holds. nlohmann converts any number to
// any arithmetic type unchecked (a fraction or a huge number into an int is
// undefined behaviour or a silently different value), so readers ask first.
template <class T>
bool holds_integer(const nlohmann::json& value) {
  if (value.is_number_unsigned()) return std::in_range<T>(value.get<uint64_t>());
  return value.is_number_integer() && std::in_range<T>(value.get<int64_t>());
}

// `value` as a T, or tega::Error naming `file` and the field `name`: integers
// must be integers within T's range, floating-point numbers finite within
// T's range, booleans booleans; other types convert as nlohmann does.
template <class T>
T json_as(const nlohmann::json& value, const std::string& name, const std::filesystem::path& file) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!value.is_boolean()) throw Error(file, "'" + name + "' must be true or false");
    return value.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    if (!holds_integer<T>(value))
      throw Error(file, "'" + name + "' must be an integer from " + std::to_string(std::numeric_limits<T>::min()) +
                            " to " + std::to_string(std::numeric_limits<T>::max()));
    return value.is_number_unsigned() ? static_cast<T>(value.get<uint64_t>()) : static_cast<T>(value.get<int64_t>());
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!value.is_number()) throw Error(file, "'" + name + "' must be a number");
    const double number = value.get<double>();
    if (!std::isfinite(number) || std::abs(number) > double(std::numeric_limits<T>::max()))
      throw Error(file, "'" + name + "' is not a finite number within range");
    return static_cast<T>(number);
  } else {
    try {
      return value.get<T>();
    } catch (const nlohmann::json::exception&) {
      throw Error(file, "'" + name + "' has the wrong type");
    }
  }
}

}  // namespace tega::detail
