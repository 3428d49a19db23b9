#pragma once
// Running the real `transgi` (or mpirun) as a child process in a test, to
// kill it, limit it and read what it printed (bake_fault_test.cpp,
// mpi_bake_test.cpp).
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace child_process {

namespace fs = std::filesystem;

inline std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline std::string text_of(const fs::path& p) {
  const auto b = bytes_of(p);
  return std::string(b.begin(), b.end());
}

// Starts the command with stdout and stderr into `log`; `file_limit` > 0
// caps the size of any file it writes, as a full disk would.
inline pid_t spawn(const std::vector<std::string>& args, const fs::path& log, rlim_t file_limit = 0) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  std::FILE* f = std::fopen(log.c_str(), "w");
  if (f) {
    ::dup2(::fileno(f), 1);
    ::dup2(::fileno(f), 2);
  }
  if (file_limit > 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // a write past the limit then fails with EFBIG, as on a full disk
    const rlimit r{file_limit, file_limit};
    ::setrlimit(RLIMIT_FSIZE, &r);
  }
  std::vector<char*> argv;
  for (const std::string& s : args) argv.push_back(const_cast<char*>(s.c_str()));
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());
  ::_exit(127);
}

inline int wait_exit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

}  // namespace child_process
