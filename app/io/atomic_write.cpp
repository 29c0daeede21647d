#include "io/atomic_write.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include "io/input_error.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;

constexpr std::string_view kTag = ".gvio-tmp-";

// errno's text after a failed write ("No space left on device", "File too large"); streams do not
// keep the error of the write that failed, so errno is trusted only for the errors a write has.
std::string writeFailure(int error) {
  const bool write_error = error == ENOSPC || error == EFBIG || error == EDQUOT || error == EIO;
  return write_error ? std::string("write failed: ") + std::strerror(error)
                     : std::string("write failed (disk full?)");
}

// The PID in a temporary's name, 0 when the name is not one of ours.
long temporaryPid(const std::string& name) {
  const std::size_t tag = name.find(kTag);
  if (name.empty() || name.front() != '.' || tag == std::string::npos) return 0;
  const char* begin = name.data() + tag + kTag.size();
  long pid = 0;
  const auto [end, ec] = std::from_chars(begin, name.data() + name.size(), pid);
  return ec == std::errc() && end != begin && *end == '-' ? pid : 0;
}

}  // namespace

fs::path createTemporarySibling(const fs::path& path, std::string_view suffix) {
  // The PID lets a later run tell a dead process's leftovers from a running one's; the random
  // part keeps concurrent writers in one process (threads) apart, O_EXCL makes the name ours.
  std::random_device entropy;
  const std::string stem = "." + path.filename().string() + std::string(kTag) +
                           std::to_string(static_cast<long>(::getpid())) + "-";
  int error = 0;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const fs::path tmp =
        path.parent_path() / (stem + std::to_string(entropy()) + std::string(suffix));
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return tmp;
    }
    error = errno;
    if (error != EEXIST) break;
  }
  throw InputError(path, 0,
                   std::string("cannot write (") + std::strerror(error) +
                       "; missing directory or no permission?)");
}

void moveIntoPlace(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw InputError(path, 0, "cannot rename temporary file into place: " + ec.message());
  }
}

void writeViaPathAtomic(const fs::path& path, std::string_view suffix,
                        const std::function<void(const fs::path& tmp)>& write) {
  const fs::path tmp = createTemporarySibling(path, suffix);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
    throw;
  }
  moveIntoPlace(tmp, path);
}

void writeFolderAtomic(const fs::path& dir, const std::function<void(const fs::path& tmp)>& write) {
  const fs::path tmp = createTemporarySibling(dir);
  std::error_code ec;
  fs::remove(tmp, ec);
  if (!ec) fs::create_directory(tmp, ec);
  if (ec) throw InputError(dir, 0, "cannot write the folder: " + ec.message());
  try {
    write(tmp);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  if (fs::exists(dir)) fs::remove_all(dir, ec);
  if (!ec) fs::rename(tmp, dir, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
    throw InputError(dir, 0, "cannot write the folder: " + ec.message());
  }
}

void writeFileAtomic(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  const fs::path tmp = createTemporarySibling(path);
  auto discard = [&tmp] {
    std::error_code ignored;
    fs::remove(tmp, ignored);
  };
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) {
    discard();
    throw InputError(path, 0, "cannot write (missing directory or no permission)");
  }
  try {
    write(out);
  } catch (...) {
    out.close();
    discard();  // never leave a half-written temporary behind
    throw;
  }
  out.flush();
  out.close();  // closing flushes the last buffer: a full disk may only show here
  if (out.fail()) {
    const int error = errno;
    discard();
    throw InputError(path, 0, writeFailure(error));
  }
  moveIntoPlace(tmp, path);
}

void writeTextAtomic(const fs::path& path, std::string_view text) {
  writeFileAtomic(path, [&](std::ostream& out) { out << text; });
}

bool isTemporaryName(const fs::path& file) {
  return temporaryPid(file.filename().string()) > 0;
}

std::vector<fs::path> removeStaleTemporaries(const fs::path& dir) {
  std::vector<fs::path> removed;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const long pid = temporaryPid(entry.path().filename().string());
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    // kill(pid, 0) probes without signalling: ESRCH means no such process any more.
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    if (fs::remove(entry.path(), ignored)) removed.push_back(entry.path());
  }
  return removed;
}

}  // namespace gvio::io
