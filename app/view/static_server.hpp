#pragma once
// `gvio view --serve`: the site's folder served read-only over HTTP on the loopback interface
// (cpp-httplib, Debian's libcpp-httplib-dev), for browsers or tools that will not load a page's
// scripts from file://.
#include <atomic>
#include <filesystem>
#include <functional>

namespace gvio::view {

// Serves `dir` on 127.0.0.1:`port` (0: a free port) until `stop()` returns true (polled every
// 100 ms). `on_listening` gets the port once the socket is bound. Throws InputError naming `dir`
// when the port cannot be bound.
void serveFolder(const std::filesystem::path& dir, int port,
                 const std::function<void(int port)>& on_listening,
                 const std::function<bool()>& stop);

}  // namespace gvio::view
