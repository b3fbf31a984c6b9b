// Whole-or-nothing output files: see output_file.h.
#include "core/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/error.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// The reason a file in `path`'s directory cannot be created, phrased for the user.
std::string create_failure(const std::string& path, int error) {
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::exists(parent, ec))
    return "cannot write: directory '" + parent.string() + "' does not exist";
  if (!parent.empty() && !fs::is_directory(parent, ec))
    return "cannot write: '" + parent.string() + "' is not a directory";
  return std::string("cannot write: ") + std::strerror(error);
}

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  if (fs::is_directory(path_, ec)) throw InputError(path_, "cannot write: it is a directory");
  // "<name>.tmp-<host>-<pid><ext>": unique per process even when processes on several
  // machines write into one shared directory (cluster jobs), in the same directory, and
  // keeping the extension (OpenImageIO picks the format by it).
  char host[256] = "host";
  ::gethostname(host, sizeof host - 1);
  host[sizeof host - 1] = '\0';
  const fs::path p(path_);
  temp_ = (p.parent_path() / (p.stem().string() + ".tmp-" + host + "-" + std::to_string(::getpid()) +
                              p.extension().string()))
              .string();
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int error = errno;  // before anything else can change it
    throw InputError(path_, create_failure(path_, error));
  }
  ::close(fd);
}

OutputFile::~OutputFile() {
  if (!committed_) ::unlink(temp_.c_str());
}

void OutputFile::commit() {
  if (::rename(temp_.c_str(), path_.c_str()) != 0) {
    const int error = errno;
    throw InputError(path_, std::string("cannot write: ") + std::strerror(error));
  }
  committed_ = true;
}

void write_text_file(const std::string& path, const std::string& text) {
  OutputFile file(path);
  std::FILE* f = std::fopen(file.temp_path().c_str(), "wb");
  if (!f) {
    const int error = errno;
    throw InputError(path, std::string("cannot write: ") + std::strerror(error));
  }
  const std::size_t written = std::fwrite(text.data(), 1, text.size(), f);
  const int write_error = written == text.size() ? 0 : errno;
  const int close_error = std::fclose(f) == 0 ? 0 : errno;
  if (written != text.size() || close_error != 0)
    throw InputError(path, std::string("cannot write: ") +
                               std::strerror(write_error ? write_error : close_error ? close_error : EIO));
  file.commit();
}

}  // namespace speculum
