// JSON that speculum prints or writes: every document is built as an nlohmann::json value (so
// strings such as file paths are always escaped) and laid out by the helpers here.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

namespace speculum::cli {

// Key order as inserted: the printed objects keep the order their fields were always printed in.
using OrderedJson = nlohmann::ordered_json;

// One line, `{"key": value, "key": [1, 2]}`: the layout of the --json output that scripts and
// tests match with `"key": value` patterns (nlohmann's own compact dump has no spaces).
// Strings that are not valid UTF-8 (file names may be any bytes) get U+FFFD in their place.
std::string json_line(const OrderedJson& value);

// `value` with `decimals` places (the number `%.<decimals>f` prints), for timings, ratios and
// sums whose further digits are noise; JSON prints the shortest text that reads back to it,
// so at most `decimals` places.
double rounded(double value, int decimals);

// A counter: integral values as JSON integers whatever the counter's arithmetic type
// (2.0 prints as 2), others as JSON numbers, non-finite ones as null.
template <class T>
nlohmann::json counter_json(T value) {
  static_assert(std::is_arithmetic_v<T>);
  if constexpr (std::is_floating_point_v<T>) {
    constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
    if (std::isfinite(value) && value == std::trunc(value) && std::abs(double(value)) < kExactIntegers)
      return static_cast<std::int64_t>(value);
  }
  return value;
}

// A name → counter map as a JSON object (keys in the map's order).
template <class Map>
nlohmann::json counters_json(const Map& counters) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, value] : counters) out[name] = counter_json(value);
  return out;
}

// `name=value name=value`, the values as counter_json prints them.
template <class Map>
std::string counters_text(const Map& counters) {
  std::string s;
  for (const auto& [name, value] : counters) s += (s.empty() ? "" : " ") + name + "=" + counter_json(value).dump();
  return s;
}

// A file: indented, with a final newline; invalid UTF-8 replaced as in json_line.
std::string json_document(const nlohmann::json& value);

}  // namespace speculum::cli
