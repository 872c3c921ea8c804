#include "seam/io/file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include "seam/io/bpt.h"
#include "seam/io/json.h"

namespace seam::io {

namespace {

namespace fs = std::filesystem;

Status ioError(const fs::path& file, const std::string& problem) {
  return {ErrorCode::kIoError, file.string() + ": " + problem};
}

std::string errnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

std::string lowercase(std::string s) {
  for (char& c : s) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return s;
}

/// A temporary name next to `file` that no other writer (thread or process) uses at the same time.
fs::path temporaryNameFor(const fs::path& file) {
  static std::atomic<unsigned long> counter{0};
  const unsigned long n = counter.fetch_add(1);
  fs::path name = file;
  name.replace_filename(fmt::format(".{}.tmp.{}.{}", file.filename().string(), ::getpid(), n));
  return name;
}

/// Writes all of `content` to `fd`, retrying on short writes and EINTR; returns 0 or an errno value.
int writeAll(int fd, const std::string& content) {
  const char* data = content.data();
  size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += written;
    left -= static_cast<size_t>(written);
  }
  return 0;
}

}  // namespace

Result<std::string> readFile(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (!fs::exists(status)) return ioError(file, "cannot read file: no such file");
  if (fs::is_directory(status)) return ioError(file, "cannot read file: it is a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) return ioError(file, "cannot open file: " + errnoText(errno));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return ioError(file, "error while reading file");
  return buffer.str();
}

Status writeFileAtomically(const fs::path& file, const std::string& content) {
  if (file.filename().empty()) return ioError(file, "cannot write: the path names no file");
  const fs::path temp = temporaryNameFor(file);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) return ioError(file, "cannot create temporary file " + temp.string() + ": " + errnoText(errno));
  // Replacing a file keeps its permission bits (a new file gets 0666 minus the umask).
  struct stat existing {};
  if (::stat(file.c_str(), &existing) == 0) ::fchmod(fd, existing.st_mode & 07777);
  int err = writeAll(fd, content);
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    ::unlink(temp.c_str());
    return ioError(file, "cannot write temporary file " + temp.string() + ": " + errnoText(err));
  }
  if (::rename(temp.c_str(), file.c_str()) != 0) {
    err = errno;
    ::unlink(temp.c_str());
    return ioError(file, "cannot replace file: " + errnoText(err));
  }
  // Make the rename itself durable; failing to sync the folder does not undo a completed write.
  fs::path folder = file.parent_path();
  if (folder.empty()) folder = ".";
  const int dirFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dirFd >= 0) {
    ::fsync(dirFd);
    ::close(dirFd);
  }
  return Status::ok();
}

Result<Model> readModel(const fs::path& file) {
  const std::string ext = lowercase(file.extension().string());
  if (ext == ".json") return readModelJson(file);
  if (ext == ".bpt") return readBpt(file);
  if (ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs") {
    return Status(ErrorCode::kUnsupported,
                  file.string() + ": STEP/IGES support needs a build with SEAM_WITH_OCCT");
  }
  if (ext.empty()) {
    return Status(ErrorCode::kUnsupported,
                  file.string() + ": no file extension, cannot tell the format (supported: .json, .bpt)");
  }
  return Status(ErrorCode::kUnsupported, file.string() + ": unsupported file extension \"" +
                                             file.extension().string() + "\" (supported: .json, .bpt)");
}

}  // namespace seam::io
