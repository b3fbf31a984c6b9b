// A node's counter in a frame's report, for the tests that check what a pass counted.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"

namespace speculum::pipeline {

// The counter `name` of node `node` in `r`'s report; a test failure (and -1) when absent.
inline double node_counter(const FrameResult& r, const std::string& node, const std::string& name) {
  const par::NodeRecord* n = r.report.find(node);
  if (!n || !n->counters.count(name)) {
    ADD_FAILURE() << "no counter " << node << "/" << name;
    return -1.0;
  }
  return n->counters.at(name);
}

}  // namespace speculum::pipeline
