// Errors about bad input: always name the file (or scene) and the problem in one line.
#pragma once

#include <stdexcept>
#include <string>

namespace speculum {

// Thrown for anything wrong with user input (files, scene names, options). The CLI
// prints what() on one line and exits with status 2.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& source, const std::string& problem)
      : std::runtime_error(source + ": " + problem), source_(source), problem_(problem) {}
  const std::string& source() const { return source_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string source_;
  std::string problem_;
};

}  // namespace speculum
