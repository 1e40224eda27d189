#include "boicp/io/frame_tree.hpp"

#include <map>
#include <set>
#include <utility>

namespace boicp {
namespace {

std::string FrameName(const std::string& name) {
  return !name.empty() && name.front() == '/' ? name.substr(1) : name;
}

struct Parent {
  std::string frame;
  Transform parent_child;
};

// The root of `frame`'s tree and T_root_frame.
std::pair<std::string, Transform> FromRoot(const std::map<std::string, Parent>& parents,
                                           const std::string& frame) {
  std::string at = frame;
  Transform root_frame = Transform::Identity();
  for (size_t hops = 0;; ++hops) {
    const auto parent = parents.find(at);
    if (parent == parents.end()) return {at, root_frame};
    if (hops > parents.size()) {
      throw InputError("the tf tree runs in a cycle through frame '" + frame + "'");
    }
    root_frame = parent->second.parent_child * root_frame;
    at = parent->second.frame;
  }
}

}  // namespace

std::optional<Transform> TransformBetween(const std::vector<FrameTransform>& transforms,
                                          const std::string& from, const std::string& to) {
  const std::string a = FrameName(from), b = FrameName(to);
  if (a == b) return Transform::Identity();
  std::map<std::string, Parent> parents;
  std::set<std::string> frames;
  for (const FrameTransform& t : transforms) {
    parents[FrameName(t.child)] = {FrameName(t.parent), t.parent_child};
    frames.insert(FrameName(t.child));
    frames.insert(FrameName(t.parent));
  }
  if (frames.count(a) == 0 || frames.count(b) == 0) return std::nullopt;
  const auto [root_a, root_from] = FromRoot(parents, a);
  const auto [root_b, root_to] = FromRoot(parents, b);
  if (root_a != root_b) return std::nullopt;
  return Transform(root_from.inverse() * root_to);
}

}  // namespace boicp
