#pragma once
// File helpers shared by every reader and writer: the input checks (a regular file of bounded size, so that a FIFO,
// /dev/zero or a directory is refused instead of blocking or exhausting memory) and the atomic writer.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io {

/// Largest model file that the text readers (.json, .bpt) load into memory: 256 MiB. A JSON model of 10^6 control
/// points is about 60 MB; parsing holds several times the file's size in memory, so larger files are refused with a
/// message instead of running out of memory.
inline constexpr std::uintmax_t kMaxModelFileBytes = std::uintmax_t{256} << 20;

/// Largest STEP/IGES file handed to OpenCASCADE: 2 GiB (real assemblies reach a few hundred MB).
inline constexpr std::uintmax_t kMaxCadFileBytes = std::uintmax_t{2} << 30;

/// Checks that `file` names an existing regular file (symbolic links followed) of at most `maxBytes` bytes, without
/// opening it. kIoError naming the file otherwise: "cannot read file: no such file", "cannot read file: it is a
/// directory", "cannot read file: not a regular file (a FIFO)" (or a character device, a block device, a socket),
/// "cannot read file: too large (N bytes, at most M are read)".
Status checkInputFile(const std::filesystem::path& file, std::uintmax_t maxBytes = kMaxModelFileBytes);

/// Reads a whole file after checkInputFile (a FIFO or a device is never opened for reading, so it cannot block);
/// kIoError naming the file when it cannot be read.
Result<std::string> readFile(const std::filesystem::path& file, std::uintmax_t maxBytes = kMaxModelFileBytes);

/// Checks that `file` may be written: it does not exist yet, or it is a regular file (not a symbolic link, a FIFO,
/// a device node or a directory, which an atomic rename would silently replace). kIoError naming the file otherwise:
/// "refusing to replace a symbolic link", "refusing to replace a FIFO", ..., "it is a directory".
Status checkOutputFile(const std::filesystem::path& file);

/// A short temporary name in the folder of `file`, unique within this process and across processes
/// (".seam-<pid>-<n>.tmp"): short on purpose, so that a legal output name of up to 255 bytes still works. For writers
/// that rename a temporary over their output (the STEP/IGES writer); create it with O_EXCL.
std::filesystem::path temporaryPathFor(const std::filesystem::path& file);

/// Removes a file when it goes out of scope, unless keep() was called: a temporary output before it is renamed into
/// place, or a scratch file. Never throws (a file that cannot be removed stays; removeTemporaryFiles sweeps those
/// temporaryPathFor named).
class RemoveOnExit {
 public:
  explicit RemoveOnExit(std::filesystem::path path) : path_(std::move(path)) {}
  RemoveOnExit(const RemoveOnExit&) = delete;
  RemoveOnExit& operator=(const RemoveOnExit&) = delete;
  ~RemoveOnExit() {
    std::error_code ec;
    if (!keep_) std::filesystem::remove(path_, ec);
  }
  void keep() { keep_ = true; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  bool keep_ = false;
};

/// Removes every temporary file temporaryPathFor named in this process that still exists (those renamed over their
/// outputs are gone already): for a process that must end at once (the CLI's --time-limit), so that no temporary is
/// left behind. Thread-safe.
void removeTemporaryFiles();

/// Writes `content` to a temporary file next to `file` (a short name ".seam-<pid>-<n>.tmp", so that any legal file
/// name works), then renames it over `file`: never a partial file. Refuses what checkOutputFile refuses.
Status writeFileAtomically(const std::filesystem::path& file, const std::string& content);

/// writeFileAtomically with the content made piece by piece: `produce(emit)` calls `emit(text)` for each piece in
/// order, and each piece is written at once, so that a large output is never held whole in memory (a 48 MB healed
/// model: 100 MB of the process's peak while its text was built). An error of a write ends the output (later pieces
/// are dropped) and is returned; the temporary file is removed then, as on any failure.
Status writeFileAtomically(const std::filesystem::path& file,
                           const std::function<void(const std::function<void(std::string_view)>&)>& produce);

/// Reads a model by extension: .json, .bpt (Newell Bezier patch text format), and .step/.stp/.iges/.igs when the
/// program links seam::occt (the OpenCASCADE module installs its reader, see registerCadReader; its warnings and
/// per-face notes are dropped: call occt::readCadFile for them). Errors name the file: kUnsupported for an unknown
/// or missing extension (the message lists supportedModelFormats()) and for STEP/IGES in a program without
/// seam::occt; otherwise the reader's error.
Result<Model> readModel(const std::filesystem::path& file);

/// A reader of STEP/IGES files for readModel.
using CadModelReader = Result<Model> (*)(const std::filesystem::path& file);

/// Installs the STEP/IGES reader of readModel. seam::occt calls it once, during static initialisation of any program
/// that links it (the library's link interface keeps the registering object); a C++ user never needs to. Passing
/// nullptr removes it.
void registerCadReader(CadModelReader reader);

/// True when readModel reads STEP/IGES in this program (seam::occt is linked).
bool hasCadReader();

/// The formats readModel reads in this program, for messages and help texts: ".json, .bpt, .step/.stp, .iges/.igs",
/// or ".json, .bpt (STEP/IGES need a build with SEAM_WITH_OCCT)" without seam::occt.
std::string supportedModelFormats();

}  // namespace seam::io
