// JSON layout helpers: see json_output.h.
#include "apps/cli/json_output.h"

#include <cstdio>
#include <cstdlib>

namespace speculum::cli {

namespace {
constexpr auto kReplaceInvalidUtf8 = nlohmann::json::error_handler_t::replace;

template <class Json>
std::string scalar_text(const Json& value) {
  return value.dump(-1, ' ', false, kReplaceInvalidUtf8);
}
}  // namespace

std::string json_line(const OrderedJson& value) {
  if (value.is_object()) {
    std::string s = "{";
    for (auto it = value.begin(); it != value.end(); ++it)
      s += (it == value.begin() ? "" : ", ") + scalar_text(OrderedJson(it.key())) + ": " + json_line(it.value());
    return s + "}";
  }
  if (value.is_array()) {
    std::string s = "[";
    for (auto it = value.begin(); it != value.end(); ++it) s += (it == value.begin() ? "" : ", ") + json_line(*it);
    return s + "]";
  }
  return scalar_text(value);
}

double rounded(double value, int decimals) {
  if (!std::isfinite(value)) return value;
  // Through the decimal text, so the number is exactly the one `%.Nf` printed (correctly
  // rounded, unlike value * 10^N, whose product is itself rounded).
  char text[512];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return std::strtod(text, nullptr);
}

std::string json_document(const nlohmann::json& value) {
  return value.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n";
}

}  // namespace speculum::cli
