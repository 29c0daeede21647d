#pragma once
// PCL reports read errors through its console, several lines on stderr where the CLI promises
// one: silenced while reading, the failure is reported by the caller's exception instead.
#include <pcl/console/print.h>

namespace gvio::io {

class QuietPcl {
 public:
  QuietPcl() : saved_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~QuietPcl() { pcl::console::setVerbosityLevel(saved_); }
  QuietPcl(const QuietPcl&) = delete;
  QuietPcl& operator=(const QuietPcl&) = delete;

 private:
  pcl::console::VERBOSITY_LEVEL saved_;
};

}  // namespace gvio::io
