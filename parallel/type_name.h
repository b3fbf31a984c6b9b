// type_name<T>(): a readable C++ type name for graph messages, DOT labels and manifests
// (parsed from the compiler's function signature; GCC and Clang spell it "T = ...").
#pragma once

#include <string>
#include <string_view>

namespace speculum::par {

template <class T>
std::string type_name() {
  const std::string_view sig = __PRETTY_FUNCTION__;
  const auto start = sig.find("T = ");
  if (start == std::string_view::npos) return std::string(sig);
  auto rest = sig.substr(start + 4);
  // GCC appends "; std::string = ..." after the argument; Clang ends with "]".
  auto end = rest.find(';');
  if (end == std::string_view::npos) end = rest.rfind(']');
  return std::string(rest.substr(0, end));
}

}  // namespace speculum::par
