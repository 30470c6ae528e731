#include "core/io/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace aolab {

namespace fs = std::filesystem;

void require_regular_file(const std::string& path, const std::string& what_file) {
  std::error_code ec;
  const fs::file_type type = fs::status(path, ec).type();
  const char* kind = "not a regular file";
  switch (type) {
    case fs::file_type::regular:
      return;
    case fs::file_type::not_found:
      throw FileNotFound(path, what_file);
    case fs::file_type::none:  // status() failed for another reason (e.g. permissions)
      throw std::invalid_argument(what_file + " " + path + " cannot be accessed: " +
                                  (ec ? ec.message() : std::string("unknown error")));
    case fs::file_type::directory:
      kind = "a directory";
      break;
    case fs::file_type::fifo:
      kind = "a FIFO (named pipe)";
      break;
    case fs::file_type::socket:
      kind = "a socket";
      break;
    case fs::file_type::block:
      kind = "a block device";
      break;
    case fs::file_type::character:
      kind = "a character device";
      break;
    default:
      break;
  }
  throw std::invalid_argument(what_file + " " + path + " is " + kind +
                              (type == fs::file_type::unknown ? "" : ", not a regular file"));
}

WriteFailed::WriteFailed(const std::string& path, const std::string& step, int error_number)
    : std::runtime_error("cannot write " + path + ": " + step +
                         " failed: " + std::strerror(error_number)),
      path_(path),
      errno_(error_number) {}

namespace {

[[noreturn]] void write_failed(const std::string& path, const std::string& step, int error) {
  throw WriteFailed(path, step, error);
}

// The target's directory must exist and the target, if present, must be a file we may
// replace: renaming over a directory or a FIFO would surprise whoever owns it.
fs::path checked_directory(const std::string& path) {
  const fs::path target(path);
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw FileNotFound(dir.string(), "output directory");
  const fs::file_type type = fs::symlink_status(target, ec).type();
  if (type != fs::file_type::not_found && type != fs::file_type::regular &&
      type != fs::file_type::symlink)
    throw std::invalid_argument("output " + path + " exists and is not a regular file");
  return dir;
}

// "<dir>/.<name>.tmp-<pid>-<counter>": hidden, and unique across processes (pid) and across
// threads of this one (counter).
std::string temporary_path_for(const fs::path& dir, const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return (dir / ("." + fs::path(path).filename().string() + ".tmp-" +
                 std::to_string(long(getpid())) + "-" + std::to_string(counter++)))
      .string();
}

// Steps 1-3 of the header: the temporary file holds `bytes`, synced and closed. Removes it
// and throws on any failure.
void write_synced(const std::string& temporary, const std::string& path, std::string_view bytes) {
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) write_failed(path, "creating its temporary file " + temporary, errno);
  const auto fail = [&](const char* step) {
    const int error = errno;
    ::close(fd);
    ::unlink(temporary.c_str());
    write_failed(path, step, error);
  };
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("write");
    if (n == 0) {  // no progress and no error: treat as a full device rather than spin
      errno = ENOSPC;
      fail("write");
    }
    p += n;
    left -= std::size_t(n);
  }
  if (::fsync(fd) != 0) fail("fsync");
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    write_failed(path, "close", error);
  }
}

// Step 4: after the rename the directory entry is synced; a failure there is reported (the
// file is in place, but its name may not survive a power loss).
void rename_into_place(const std::string& temporary, const std::string& path, const fs::path& dir) {
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    write_failed(path, "rename", error);
  }
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return;  // a directory we may not open for reading: the rename itself held
  const int synced = ::fsync(dfd);
  const int error = errno;
  ::close(dfd);
  // EINVAL: a file system that cannot sync directories (some FUSE mounts); nothing to do.
  if (synced != 0 && error != EINVAL) write_failed(path, "fsync of its directory", error);
}

}  // namespace

void write_file_durably(const std::string& path, std::string_view bytes) {
  const fs::path dir = checked_directory(path);
  const std::string temporary = temporary_path_for(dir, path);
  write_synced(temporary, path, bytes);
  rename_into_place(temporary, path, dir);
}

void write_files_durably(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<fs::path> dirs;
  for (const auto& [path, bytes] : files) dirs.push_back(checked_directory(path));
  std::vector<std::string> temporaries;
  try {
    for (std::size_t i = 0; i < files.size(); ++i) {
      temporaries.push_back(temporary_path_for(dirs[i], files[i].first));
      write_synced(temporaries.back(), files[i].first, files[i].second);
    }
  } catch (...) {
    for (const auto& t : temporaries) ::unlink(t.c_str());
    throw;
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    try {
      rename_into_place(temporaries[i], files[i].first, dirs[i]);
    } catch (...) {
      for (std::size_t j = i + 1; j < files.size(); ++j) ::unlink(temporaries[j].c_str());
      throw;
    }
  }
}

}  // namespace aolab
