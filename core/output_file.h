// An output file appears whole or not at all: it is written under a temporary name in the
// same directory (so the rename stays on one file system and is atomic) and renamed into
// place only when complete. A failure, an exception or Ctrl-C leaves the user's path as it
// was. Errors are InputErrors naming the path the user gave, never the temporary one, with
// the operating system's reason taken where it happened (not a stale errno).
#pragma once

#include <string>

namespace speculum {

class OutputFile {
 public:
  // Creates the temporary file; throws InputError(path, "cannot write: <reason>") when it
  // cannot be (missing directory, no permission, path is a directory, ...).
  explicit OutputFile(std::string path);
  ~OutputFile();  // removes the temporary file unless committed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_; }
  // Renames the temporary file to path(); throws InputError with the reason.
  void commit();

 private:
  std::string path_, temp_;
  bool committed_ = false;
};

// `text` to `path` through an OutputFile.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace speculum
