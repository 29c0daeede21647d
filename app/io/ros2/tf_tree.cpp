#include "io/ros2/tf_tree.hpp"

#include <algorithm>
#include <map>

namespace gvio::io::ros2 {
namespace {

// A frame's pose in its tree's root, walking up parent links, and the links walked; nullopt when
// the walk does not end (a loop: more steps than links).
std::optional<std::pair<Eigen::Isometry3d, std::vector<const TfLink*>>> toRoot(
    const std::vector<TfLink>& links, std::string frame) {
  Eigen::Isometry3d T_root_frame = Eigen::Isometry3d::Identity();
  std::vector<const TfLink*> chain;
  for (std::size_t step = 0; step <= links.size(); ++step) {
    const auto up =
        std::find_if(links.begin(), links.end(), [&](const TfLink& l) { return l.child == frame; });
    if (up == links.end()) return std::make_pair(T_root_frame, chain);
    T_root_frame = up->T_parent_child * T_root_frame;
    chain.push_back(&*up);
    frame = up->parent;
  }
  return std::nullopt;
}

}  // namespace

std::string tfFrame(const std::string& name) {
  return !name.empty() && name.front() == '/' ? name.substr(1) : name;
}

std::optional<std::string> TfTree::add(const TfLink& given) {
  TfLink link = given;
  link.parent = tfFrame(link.parent);
  link.child = tfFrame(link.child);
  if (link.parent == link.child) return "a transform from " + link.parent + " to itself";
  std::vector<TfLink> next = links_;
  const auto same = std::find_if(next.begin(), next.end(),
                                 [&](const TfLink& l) { return l.child == link.child; });
  if (same != next.end()) next.erase(same);
  next.push_back(link);
  // A tf tree has one parent per frame; a loop through the new link brings the walk up from its
  // child back to it, without end.
  if (!toRoot(next, link.child)) {
    return "the link " + link.parent + " -> " + link.child + " would close a loop in the tree";
  }
  links_ = std::move(next);
  return std::nullopt;
}

std::optional<TfPath> TfTree::lookup(const std::string& a_name, const std::string& b_name) const {
  const std::string a = tfFrame(a_name), b = tfFrame(b_name);
  const auto up_a = toRoot(links_, a), up_b = toRoot(links_, b);
  if (!up_a || !up_b) return std::nullopt;
  const std::string root_a = up_a->second.empty() ? a : up_a->second.back()->parent;
  const std::string root_b = up_b->second.empty() ? b : up_b->second.back()->parent;
  if (root_a != root_b) return std::nullopt;
  // T_a_b = T_root_a^-1 T_root_b; the frames listed up from a to the root, then down to b (the
  // common ancestors' part cancels in the product, and is dropped from the list).
  TfPath path;
  path.T_a_b = up_a->first.inverse() * up_b->first;
  std::vector<std::string> from_a{a}, from_b{b};
  for (const TfLink* l : up_a->second) from_a.push_back(l->parent);
  for (const TfLink* l : up_b->second) from_b.push_back(l->parent);
  while (from_a.size() > 1 && from_b.size() > 1 &&
         from_a[from_a.size() - 2] == from_b[from_b.size() - 2]) {
    from_a.pop_back();
    from_b.pop_back();
  }
  path.frames = from_a;
  for (auto it = from_b.rbegin() + 1; it != from_b.rend(); ++it) path.frames.push_back(*it);
  std::map<std::string, bool> seen;
  for (std::size_t i = 0; i + 1 < path.frames.size(); ++i) {
    for (const TfLink& l : links_) {
      const bool joins = (l.parent == path.frames[i] && l.child == path.frames[i + 1]) ||
                         (l.child == path.frames[i] && l.parent == path.frames[i + 1]);
      if (joins && !seen[l.source]) {
        seen[l.source] = true;
        path.sources.push_back(l.source);
      }
    }
  }
  return path;
}

}  // namespace gvio::io::ros2
