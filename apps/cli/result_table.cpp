// Experiment result rows: see result_table.h.
#include "apps/cli/result_table.h"

#include <algorithm>
#include <cmath>

#include "apps/cli/progress.h"

namespace speculum::cli {

void ResultTable::add(const std::string& key, OrderedJson json, std::string text) {
  row_.push_back({key, std::move(json), std::move(text)});
}

ResultTable& ResultTable::cell(const std::string& key, const std::string& value) {
  add(key, value, value);
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, double value, int digits) {
  if (!std::isfinite(value)) {  // JSON has no inf or nan
    add(key, nullptr, std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf"));
    return *this;
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  add(key, value, text);
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, std::int64_t value) {
  add(key, value, std::to_string(value));
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, bool value) {
  add(key, value, value ? "yes" : "no");
  return *this;
}

void ResultTable::end_row() {
  if (progress_) progress_->clear();
  if (json_) {
    OrderedJson line = OrderedJson::object();
    for (Cell& c : row_) line[c.key] = std::move(c.json);
    std::fprintf(out_, "%s\n", json_line(line).c_str());
  } else {
    if (!header_printed_) {
      // Column widths are fixed by the header and the first row; wider later cells just push
      // the rest of their line right.
      widths_.clear();
      for (const Cell& c : row_) widths_.push_back(std::max<std::size_t>({c.key.size(), c.text.size(), 6}));
      for (std::size_t i = 0; i < row_.size(); ++i)
        std::fprintf(out_, "%s%*s", i ? "  " : "", static_cast<int>(widths_[i]), row_[i].key.c_str());
      std::fprintf(out_, "\n");
      header_printed_ = true;
    }
    for (std::size_t i = 0; i < row_.size(); ++i) {
      const int w = i < widths_.size() ? static_cast<int>(widths_[i]) : 0;
      std::fprintf(out_, "%s%*s", i ? "  " : "", w, row_[i].text.c_str());
    }
    std::fprintf(out_, "\n");
  }
  std::fflush(out_);
  row_.clear();
  if (progress_) progress_->step();
}

}  // namespace speculum::cli
