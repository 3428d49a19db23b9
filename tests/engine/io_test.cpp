#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/image/png.h"
#include "engine/core/install_paths.h"
#include "engine/io/atomic_file.h"

namespace fs = std::filesystem;
using namespace engine;

namespace {
fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("engine_io_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
std::span<const std::byte> bytes(const std::string& s) { return std::as_bytes(std::span(s.data(), s.size())); }
}  // namespace

TEST(AtomicFile, ReplacesContentAndLeavesNoTemporaries) {
  const fs::path dir = temp_dir();
  const fs::path f = dir / "a.bin";
  io::write_file_atomically(f, bytes("first"));
  io::write_file_atomically(f, bytes("second"));
  EXPECT_EQ(slurp(f), "second");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "temporary files were left behind";
  fs::remove_all(dir);
}

TEST(AtomicFile, FailureKeepsTheOldFileAndNamesThePath) {
  const fs::path dir = temp_dir();
  const fs::path target = dir / "sub";
  fs::create_directories(target);  // a directory where a file is wanted
  try {
    io::write_file_atomically(target, bytes("x"));
    FAIL() << "expected IoError";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(target));
  fs::remove_all(dir);
}

TEST(Png, WritesAValidSignature) {
  const fs::path dir = temp_dir();
  image::Rgb8Image img(4, 3);
  img.at(1, 1)[0] = 255;
  image::write_png(dir / "x.png", img);
  const std::string data = slurp(dir / "x.png");
  ASSERT_GE(data.size(), 8u);
  EXPECT_EQ(data.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_THROW(image::write_png(dir / "bad.png", image::Rgb8Image{}), io::IoError);
  fs::remove_all(dir);
}

// An installed program's folders (engine/core/install_paths.h).
TEST(InstallPaths, TheExecutablesFolderAndAnInstalledFoldersTwin) {
  const fs::path exe_dir = core::executable_dir();
  ASSERT_FALSE(exe_dir.empty());
  EXPECT_TRUE(fs::exists(exe_dir)) << exe_dir;
  EXPECT_FALSE(core::beside_executable("no/such/folder").has_value());
  EXPECT_EQ(core::beside_executable("."), exe_dir.lexically_normal() / "");
  const fs::path prefix = temp_dir() / "prefix";
  fs::create_directories(prefix / "share/transgi/shaders");
  fs::create_directories(prefix / "include/transgi");
  const auto twin = core::installed_twin(prefix / "share/transgi/shaders", "share/transgi/shaders", "include/transgi");
  ASSERT_TRUE(twin.has_value());
  EXPECT_TRUE(fs::equivalent(*twin, prefix / "include/transgi"));
  EXPECT_TRUE(core::installed_twin(prefix / "share/transgi/shaders/", "share/transgi/shaders", "include/transgi").has_value())
      << "a trailing slash";
  EXPECT_FALSE(core::installed_twin(prefix / "share/other/shaders", "share/transgi/shaders", "include/transgi").has_value())
      << "a folder that is not the installed one";
  EXPECT_FALSE(core::installed_twin(prefix / "share/transgi/shaders", "share/transgi/shaders", "include/none").has_value())
      << "no twin there";
  fs::remove_all(prefix);
}
