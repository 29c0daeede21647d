#pragma once
// The static part of a bag's tf2 tree (REP 105): /tf_static's transforms, and /tf links whose
// every sample is the same (a robot_state_publisher of fixed joints on /tf). A lookup composes
// the links between two frames in either direction, as tf2's lookupTransform does.
#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace gvio::io::ros2 {

// One link: child's pose in parent (p_parent = T_parent_child p_child), from `source` (a topic).
struct TfLink {
  std::string parent, child;
  Eigen::Isometry3d T_parent_child = Eigen::Isometry3d::Identity();
  std::string source;
};

struct TfPath {
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  std::vector<std::string> frames;   // a ... b, the frames the chain went through
  std::vector<std::string> sources;  // the topics the links came from, without repeats
};

class TfTree {
 public:
  // A later link of the same child replaces an earlier one (as tf2's static buffer does). A link
  // that closes a loop is refused with a reason (returned), the tree kept as it was.
  std::optional<std::string> add(const TfLink& link);

  // T_a_b (b's pose in a), or nullopt when no chain of links joins them. Frame names compare
  // without a leading '/' (tf2 strips it).
  [[nodiscard]] std::optional<TfPath> lookup(const std::string& a, const std::string& b) const;
  [[nodiscard]] bool empty() const { return links_.empty(); }
  [[nodiscard]] const std::vector<TfLink>& links() const { return links_; }

 private:
  std::vector<TfLink> links_;
};

// Frame names as tf2 compares them: without a leading '/'.
std::string tfFrame(const std::string& name);

}  // namespace gvio::io::ros2
