#include "view/static_server.hpp"

#include <httplib.h>

#include <chrono>
#include <thread>

#include "io/input_error.hpp"

namespace gvio::view {

void serveFolder(const std::filesystem::path& dir, int port,
                 const std::function<void(int port)>& on_listening,
                 const std::function<bool()>& stop) {
  httplib::Server server;
  // Only files under `dir`: cpp-httplib refuses paths that climb out of a mount point.
  if (!server.set_mount_point("/", dir.string())) {
    throw io::InputError(dir, 0, "cannot serve the folder (not a readable folder)");
  }
  server.set_file_extension_and_mimetype_mapping("js", "text/javascript");
  const int bound = port == 0 ? server.bind_to_any_port("127.0.0.1")
                              : (server.bind_to_port("127.0.0.1", port) ? port : -1);
  if (bound < 0) {
    throw io::InputError(
        dir, 0,
        "cannot listen on 127.0.0.1:" + std::to_string(port) + " (in use? choose another --port)");
  }
  std::atomic<bool> ended{false};  // the server returned on its own (a socket error)
  std::thread watcher([&] {
    while (!ended && !stop()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    server.stop();
  });
  on_listening(bound);
  server.listen_after_bind();
  ended = true;
  watcher.join();
}

}  // namespace gvio::view
