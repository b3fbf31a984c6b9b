// A graph capture of `value` as a node output, for the inspect drawing tests.
#pragma once

#include <string>
#include <typeinfo>
#include <utility>

#include "parallel/graph.h"

namespace speculum::inspect {

template <class T>
par::CapturedOutput capture(const T& value, std::string resource = "r") {
  par::CapturedOutput o;
  o.node = "n";
  o.port = o.resource = std::move(resource);
  o.type = typeid(T);
  o.type_name = "T";
  o.value = &value;
  return o;
}

}  // namespace speculum::inspect
