#pragma once
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace gvio::io {

// Debian's OctoMap is built with its debug messages on ("Reading binary octree type ...",
// "Writing N nodes ... done.") and prints them with both fprintf(stderr) and std::cerr: stderr
// (fd 2) points at /dev/null while OctoMap reads or writes, so the CLI's stderr stays its own.
// (Files are checked by io::readOccupancy before OctoMap reads them.) fd 2 is the process's:
// use it only while no other thread may log.
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    std::cerr.flush();
    saved_ = ::dup(2);
    const int null_fd = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null_fd >= 0) ::dup2(null_fd, 2);
    if (null_fd >= 0) ::close(null_fd);
  }
  ~QuietStderr() {
    std::fflush(stderr);
    std::cerr.flush();
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace gvio::io
