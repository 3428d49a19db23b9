#include "engine/io/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <random>

#include <fcntl.h>
#include <unistd.h>

namespace engine::io {

namespace {
std::string errno_text() { return std::strerror(errno); }

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};
}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(path.string() + ": cannot create directory " + dir.string() + ": " + ec.message());
  if (fs::is_directory(path, ec)) throw IoError(path.string() + ": is a directory");

  std::random_device rd;
  // Built by appending: GCC 12 at -O3 warns falsely (-Wrestrict, its bug
  // 105329) on "." + std::string&&.
  std::string name = ".";
  name += path.filename().string();
  name += '.';
  name += std::to_string(rd());
  name += ".tmp";
  const fs::path tmp = dir / name;
  {
    Fd f{::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644)};
    if (f.fd < 0) throw IoError(path.string() + ": cannot create temporary file " + tmp.string() + ": " + errno_text());
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(f.fd, bytes.data() + done, bytes.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        const std::string why = errno_text();
        fs::remove(tmp, ec);
        throw IoError(path.string() + ": write failed: " + why);
      }
      done += static_cast<std::size_t>(n);
    }
    if (::fsync(f.fd) != 0) {
      const std::string why = errno_text();
      fs::remove(tmp, ec);
      throw IoError(path.string() + ": fsync failed: " + why);
    }
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = errno_text();
    fs::remove(tmp, ec);
    throw IoError(path.string() + ": rename from temporary file failed: " + why);
  }
  Fd d{::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (d.fd >= 0) ::fsync(d.fd);  // best effort: makes the rename itself durable
}

}  // namespace engine::io
