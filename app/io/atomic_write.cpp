#include "io/atomic_write.hpp"

#include <unistd.h>

#include <fstream>
#include <string>

#include "io/input_error.hpp"

namespace gvio::io {

std::filesystem::path temporarySibling(const std::filesystem::path& path, std::string_view suffix) {
  return path.string() + ".tmp" + std::to_string(static_cast<long>(::getpid())) +
         std::string(suffix);
}

void moveIntoPlace(const std::filesystem::path& tmp, const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw InputError(path, 0, "cannot rename temporary file into place: " + ec.message());
  }
}

void writeFileAtomic(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path tmp = temporarySibling(path);
  auto discard = [&tmp] {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
  };
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, 0, "cannot write (missing directory or no permission)");
    try {
      write(out);
    } catch (...) {
      out.close();
      discard();  // never leave a half-written temporary behind
      throw;
    }
    out.flush();
    if (!out) {
      out.close();
      discard();
      throw InputError(path, 0, "write failed (disk full?)");
    }
  }
  moveIntoPlace(tmp, path);
}

void writeTextAtomic(const std::filesystem::path& path, std::string_view text) {
  writeFileAtomic(path, [&](std::ostream& out) { out << text; });
}

}  // namespace gvio::io
