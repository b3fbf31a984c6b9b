// Experiment result rows: see result_table.h.
#include "apps/cli/result_table.h"

#include <algorithm>
#include <cmath>

#include "apps/cli/progress.h"

namespace speculum::cli {

std::string json_quote(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

void ResultTable::add(const std::string& key, std::string json, std::string text) {
  row_.push_back({key, std::move(json), std::move(text)});
}

ResultTable& ResultTable::cell(const std::string& key, const std::string& value) {
  add(key, json_quote(value), value);
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, double value, int digits) {
  char text[64], json[64];
  if (!std::isfinite(value)) {
    add(key, "null", std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf"));
    return *this;
  }
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  std::snprintf(json, sizeof json, "%.17g", value);
  add(key, json, text);
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, std::int64_t value) {
  const std::string s = std::to_string(value);
  add(key, s, s);
  return *this;
}

ResultTable& ResultTable::cell(const std::string& key, bool value) {
  add(key, value ? "true" : "false", value ? "yes" : "no");
  return *this;
}

void ResultTable::end_row() {
  if (progress_) progress_->clear();
  if (json_) {
    std::string line = "{";
    for (std::size_t i = 0; i < row_.size(); ++i)
      line += (i ? ", " : "") + json_quote(row_[i].key) + ": " + row_[i].json;
    std::fprintf(out_, "%s}\n", line.c_str());
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
