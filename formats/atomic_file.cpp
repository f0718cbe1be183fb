#include "formats/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "polycube/errors.h"

namespace polycube {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw OutputError("cannot write " + path + ": " + reason);
}

// Creates a new empty file with a name no other writer uses (pid and a per-process counter, and
// O_EXCL against leftovers of a crashed run). Creating it here, rather than leaving it to the
// writer, lets us report an unwritable directory uniformly whatever the writer does.
std::string create_temp_file(const std::string& path, const fs::path& dir, const std::string& name) {
  static std::atomic<unsigned> counter{0};
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path temp = dir / ("." + name + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return temp.string();
    }
    if (errno != EEXIST) fail(path, "cannot create a file in '" + dir.string() + "': " + std::strerror(errno));
  }
  fail(path, "cannot find an unused temporary name in '" + dir.string() + "'");
}

// Forces the data to disk before the rename; otherwise, after a power loss, the rename could be
// persisted while the data is not, leaving an empty or partial file under the final name.
void sync_to_disk(const std::string& path, const std::string& temp) {
  const int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, "temporary file " + temp + " disappeared: " + std::strerror(errno));
  // EINVAL: the file system does not support syncing (e.g. some FUSE mounts); nothing to do.
  const bool ok = ::fsync(fd) == 0 || errno == EINVAL;
  const int sync_errno = errno;
  ::close(fd);
  if (!ok) fail(path, std::string("cannot flush to disk: ") + std::strerror(sync_errno));
}

}  // namespace

void write_atomically(const std::string& path, const std::function<void(const std::string& temp_path)>& writer) {
  const fs::path target(path);
  const std::string name = target.filename().string();
  if (name.empty() || name == "." || name == "..") fail(path, "not a file name");
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");

  std::error_code ec;
  const fs::file_status dir_status = fs::status(dir, ec);
  if (!fs::exists(dir_status)) fail(path, "directory '" + dir.string() + "' does not exist");
  if (!fs::is_directory(dir_status)) fail(path, "'" + dir.string() + "' is not a directory");
  if (fs::is_directory(fs::status(target, ec))) fail(path, "it is a directory");

  const std::string temp = create_temp_file(path, dir, name);
  try {
    writer(temp);
    sync_to_disk(path, temp);
  } catch (...) {
    fs::remove(temp, ec);
    throw;
  }
  // rename(2) replaces the destination atomically: readers see the old or the new file, never a mix.
  fs::rename(temp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    fail(path, ec.message());
  }
}

void write_text_atomically(const std::string& path, const std::function<void(std::ostream& out)>& writer) {
  write_atomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) fail(path, "cannot open temporary file " + temp);
    writer(out);
    out.flush();
    if (!out) fail(path, "error while writing (disk full?)");
    out.close();
    if (out.fail()) fail(path, "error while closing (disk full?)");
  });
}

}  // namespace polycube
