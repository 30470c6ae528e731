// Files: how AO Lab opens a file it reads and writes a file it produces, in one place for
// every format (images, sidecars, meshes, and through the bindings every file the Python
// side writes).
//
// Reading: a path is checked to be a regular file before it is opened or hashed, so a FIFO
// never blocks the reader and a directory never gives a reader's obscure error.
//
// Writing is durable and atomic: a write either replaces the target with the complete new
// contents or leaves the target exactly as it was, and it always removes its temporary file:
//   1. the bytes go to a fresh temporary file beside the target (same directory, so the
//      rename stays within one file system), created with O_EXCL;
//   2. every write(2) is checked and a short write retried, so ENOSPC and EIO are reported;
//   3. fsync(2) makes the data durable (a delayed-allocation file system may report a full
//      disk only here), and close(2) is checked too;
//   4. rename(2) replaces the target atomically; the directory is then fsynced so that the
//      new name survives a power loss.
// Any failure removes the temporary file and throws WriteFailed
// "cannot write <path>: <step> failed: <reason>" (docs/conventions.md, "Writing files").
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace aolab {

/// A file that was expected to exist does not (Python: FileNotFoundError).
class FileNotFound : public std::runtime_error {
 public:
  /// `what_file` says which file it was, e.g. "EXR file" or "camera sidecar";
  /// what() is "<what_file> not found: <path>".
  FileNotFound(const std::string& path, const std::string& what_file)
      : std::runtime_error(what_file + " not found: " + path),
        path_(path),
        description_(what_file + " not found") {}
  const std::string& path() const { return path_; }
  /// what() without the path, e.g. "EXR file not found".
  const std::string& description() const { return description_; }

 private:
  std::string path_, description_;
};

/// Writing a file failed (Python: OSError with the errno): what() is
/// "cannot write <path>: <step> failed: <reason>".
class WriteFailed : public std::runtime_error {
 public:
  WriteFailed(const std::string& path, const std::string& step, int error_number);
  const std::string& path() const { return path_; }
  int error_number() const { return errno_; }

 private:
  std::string path_;
  int errno_;
};

/// Checks that `path` (after following symbolic links) is a regular file before it is opened:
/// throws FileNotFound if nothing is there, std::invalid_argument "<what_file> <path> is a
/// directory|FIFO (named pipe)|socket|block device|character device|..., not a regular file"
/// otherwise.
void require_regular_file(const std::string& path, const std::string& what_file);

/// Replaces `path` by `bytes` as described above. Throws FileNotFound if the directory does
/// not exist, std::invalid_argument if `path` exists and is not a regular file (a directory,
/// a FIFO, a device), WriteFailed if any step fails.
void write_file_durably(const std::string& path, std::string_view bytes);

/// Files that belong together (an EXR and its camera sidecar): every temporary is written and
/// synced first, and only then are they renamed into place, one after the other, so that a
/// full disk never leaves a new file beside a stale partner. (path, bytes) pairs.
void write_files_durably(const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace aolab
