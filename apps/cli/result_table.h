// The rows an experiment prints: an aligned text table for people, or with --json one JSON
// object per row (one per line) for scripts. Rows stream out as soon as they are complete,
// so a long sweep shows progress.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/cli/json_output.h"

namespace speculum::cli {

class Progress;

class ResultTable {
 public:
  explicit ResultTable(bool json, std::FILE* out = stdout) : json_(json), out_(out) {}

  // Cells of the current row, in column order. Numbers print with `digits` decimals in the
  // text table and with full precision in JSON.
  ResultTable& cell(const std::string& key, const std::string& value);
  ResultTable& cell(const std::string& key, const char* value) { return cell(key, std::string(value)); }
  ResultTable& cell(const std::string& key, double value, int digits = 2);
  ResultTable& cell(const std::string& key, std::int64_t value);
  ResultTable& cell(const std::string& key, int value) { return cell(key, std::int64_t{value}); }
  ResultTable& cell(const std::string& key, bool value);
  // Prints the current row (the header first, before the first row in text mode).
  void end_row();
  // A progress bar stepped once per row (and cleared while the row prints); may be null.
  void set_progress(Progress* progress) { progress_ = progress; }

 private:
  struct Cell {
    std::string key;
    OrderedJson json;
    std::string text;
  };
  void add(const std::string& key, OrderedJson json, std::string text);
  bool json_;
  std::FILE* out_;
  Progress* progress_ = nullptr;
  bool header_printed_ = false;
  std::vector<std::size_t> widths_;
  std::vector<Cell> row_;
};

}  // namespace speculum::cli
