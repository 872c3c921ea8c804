#include "seam/io/file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

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

/// How many temporary names writeFileAtomically tries before giving up (a name is taken only when a stale temporary
/// of an earlier process with the same id is still there).
constexpr int kMaxTemporaryAttempts = 100;

/// "a FIFO", "a character device", ... for a file type that is neither a regular file nor a directory.
std::string kindOf(mode_t mode) {
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISDIR(mode)) return "a directory";
  return "not a regular file";
}

/// Writes all of `content` to `fd`, retrying on short writes and EINTR; returns 0 or an errno value.
int writeAll(int fd, std::string_view content) {
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

// Short on purpose: a name derived from the output's own name would exceed the file system's limit (255 bytes)
// for long but legal output names.
namespace {
/// Every temporary name handed out, for removeTemporaryFiles (leaked on purpose: a watchdog thread may use it while
/// the process exits).
struct TemporaryNames {
  std::mutex mutex;
  std::vector<std::string> names;
};
TemporaryNames& temporaryNames() {
  static TemporaryNames* t = new TemporaryNames;
  return *t;
}
}  // namespace

fs::path temporaryPathFor(const fs::path& file) {
  static std::atomic<unsigned long> counter{0};
  const unsigned long n = counter.fetch_add(1);
  fs::path name = file;
  name.replace_filename(fmt::format(".seam-{}-{}.tmp", ::getpid(), n));
  TemporaryNames& t = temporaryNames();
  const std::lock_guard<std::mutex> lock(t.mutex);
  t.names.push_back(name.string());
  return name;
}

void removeTemporaryFiles() {
  TemporaryNames& t = temporaryNames();
  const std::lock_guard<std::mutex> lock(t.mutex);
  for (const std::string& name : t.names) ::unlink(name.c_str());  // renamed or removed ones: ENOENT, harmless
}

Status checkInputFile(const fs::path& file, std::uintmax_t maxBytes) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) {
    const int err = errno;  // captured before anything else can change it
    if (err == ENOENT || err == ENOTDIR) return ioError(file, "cannot read file: no such file");
    return ioError(file, "cannot read file: " + errnoText(err));
  }
  if (S_ISDIR(st.st_mode)) return ioError(file, "cannot read file: it is a directory");
  if (!S_ISREG(st.st_mode)) return ioError(file, "cannot read file: not a regular file (" + kindOf(st.st_mode) + ")");
  if (static_cast<std::uintmax_t>(st.st_size) > maxBytes) {
    return ioError(file, fmt::format("cannot read file: too large ({} bytes, at most {} are read)", st.st_size,
                                     maxBytes));
  }
  return Status::ok();
}

Result<std::string> readFile(const fs::path& file, std::uintmax_t maxBytes) {
  if (Status s = checkInputFile(file, maxBytes); !s) return s;
  // O_NONBLOCK: should the file have been replaced by a FIFO since the check, opening it does not block.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    return ioError(file, "cannot open file: " + errnoText(err));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return ioError(file, "cannot read file: not a regular file");
  }
  std::string content;
  try {
    content.reserve(static_cast<size_t>(st.st_size));
    constexpr size_t kChunk = size_t{1} << 16;  // bytes per read call
    char buffer[kChunk];
    while (true) {
      const ssize_t got = ::read(fd, buffer, kChunk);
      if (got < 0) {
        const int err = errno;
        if (err == EINTR) continue;
        ::close(fd);
        return ioError(file, "error while reading file: " + errnoText(err));
      }
      if (got == 0) break;
      content.append(buffer, static_cast<size_t>(got));
      if (content.size() > maxBytes) {  // the file grew while being read
        ::close(fd);
        return ioError(file, fmt::format("cannot read file: too large (more than {} bytes)", maxBytes));
      }
    }
  } catch (const std::bad_alloc&) {
    ::close(fd);
    return ioError(file, fmt::format("cannot read file: too large to hold in memory ({} bytes)", st.st_size));
  }
  ::close(fd);
  return content;
}

Status checkOutputFile(const fs::path& file) {
  if (file.filename().empty()) return ioError(file, "cannot write: the path names no file");
  struct stat st {};
  if (::lstat(file.c_str(), &st) != 0) return Status::ok();  // does not exist yet (or the folder is missing)
  if (S_ISREG(st.st_mode)) return Status::ok();
  if (S_ISDIR(st.st_mode)) return ioError(file, "cannot write: it is a directory");
  return ioError(file, "cannot write: refusing to replace " + kindOf(st.st_mode) +
                           " (only a regular file or a new name can be an output)");
}

Status writeFileAtomically(const fs::path& file, const std::string& content) {
  return writeFileAtomically(file, [&](const std::function<void(std::string_view)>& emit) { emit(content); });
}

Status writeFileAtomically(const fs::path& file,
                           const std::function<void(const std::function<void(std::string_view)>&)>& produce) {
  if (Status s = checkOutputFile(file); !s) return s;
  fs::path temp;
  int fd = -1;
  for (int attempt = 0; attempt < kMaxTemporaryAttempts && fd < 0; ++attempt) {
    temp = temporaryPathFor(file);
    fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const int err = errno;
    return ioError(file, "cannot create temporary file " + temp.string() + ": " + errnoText(err));
  }
  // Replacing a file keeps its permission bits (a new file gets 0666 minus the umask).
  struct stat existing {};
  if (::stat(file.c_str(), &existing) == 0) ::fchmod(fd, existing.st_mode & 07777);
  int err = 0;
  try {
    produce([&](std::string_view piece) {
      if (err == 0) err = writeAll(fd, piece);
    });
  } catch (...) {  // the producer failed (out of memory): nothing is left behind
    ::close(fd);
    ::unlink(temp.c_str());
    throw;
  }
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;  // (errno read right after each failing call)
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

namespace {

/// The STEP/IGES reader installed by seam::occt (registerCadReader), null without it. Set during static
/// initialisation, before main, and only read afterwards.
std::atomic<CadModelReader>& cadReaderSlot() {
  static std::atomic<CadModelReader> reader{nullptr};
  return reader;
}

}  // namespace

void registerCadReader(CadModelReader reader) { cadReaderSlot().store(reader); }

bool hasCadReader() { return cadReaderSlot().load() != nullptr; }

std::string supportedModelFormats() {
  return hasCadReader() ? ".json, .bpt, .step/.stp, .iges/.igs"
                        : ".json, .bpt (STEP/IGES need a build with SEAM_WITH_OCCT)";
}

Result<Model> readModel(const fs::path& file) {
  const std::string ext = lowercase(file.extension().string());
  if (ext == ".json" || ext == ".bpt") {
    try {
      return ext == ".json" ? readModelJson(file) : readBpt(file);
    } catch (const std::bad_alloc&) {
      return ioError(file, "the model is too large: out of memory while reading it");
    }
  }
  if (ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs") {
    if (const CadModelReader reader = cadReaderSlot().load()) return reader(file);
    return Status(ErrorCode::kUnsupported,
                  file.string() + ": STEP/IGES support needs a build with SEAM_WITH_OCCT, linking seam::occt");
  }
  if (ext.empty()) {
    return Status(ErrorCode::kUnsupported, file.string() + ": no file extension, cannot tell the format (supported: " +
                                               supportedModelFormats() + ")");
  }
  return Status(ErrorCode::kUnsupported, file.string() + ": unsupported file extension \"" +
                                             file.extension().string() + "\" (supported: " +
                                             supportedModelFormats() + ")");
}

}  // namespace seam::io
