// A bag's scans: its PointCloud2 topic's messages in a time window, each
// with its header stamp and, from an odometry topic, a prior.

#include "boicp/io/bag_scans.hpp"

#include <algorithm>
#include <cmath>

#include "boicp/io/frame_tree.hpp"
#include "io/io_readers.hpp"

namespace boicp {
namespace {

constexpr double kNanosecondsPerSecond = 1e9;

std::string TopicList(const std::vector<BagTopic>& topics, bool (*keep)(const std::string&)) {
  std::string list;
  for (const BagTopic& topic : topics) {
    if (keep != nullptr && !keep(topic.type)) continue;
    list += (list.empty() ? "" : ", ") + topic.name + " (" + topic.type + ", " +
            std::to_string(topic.messages) + " messages)";
  }
  return list.empty() ? "none" : list;
}

const BagTopic* FindTopic(const std::vector<BagTopic>& topics, const std::string& name) {
  for (const BagTopic& topic : topics) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

// The topic named `name` of a type `is_type` accepts; `what` names its role in errors.
const BagTopic& RequireTopic(const std::string& path, const std::vector<BagTopic>& topics,
                             const std::string& name, bool (*is_type)(const std::string&),
                             const std::string& what) {
  const BagTopic* topic = FindTopic(topics, name);
  if (topic == nullptr) {
    throw InputError(path + ": no topic " + name + "; its " + what +
                     " topics: " + TopicList(topics, is_type));
  }
  if (!is_type(topic->type)) {
    throw InputError(path + ": topic " + name + " holds " + topic->type + ", not " + what);
  }
  return *topic;
}

// The scan topic: the one named, else the bag's only PointCloud2 topic.
const BagTopic& ScanTopic(const std::string& path, const std::vector<BagTopic>& topics,
                          const std::string& name) {
  if (!name.empty()) return RequireTopic(path, topics, name, IsPointCloud2Type, "PointCloud2");
  const BagTopic* only = nullptr;
  int clouds = 0;
  for (const BagTopic& topic : topics) {
    if (IsPointCloud2Type(topic.type)) {
      only = &topic;
      ++clouds;
    }
  }
  if (clouds == 1) return *only;
  if (clouds == 0) {
    throw InputError(
        path + ": no sensor_msgs/PointCloud2 topic; its topics: " + TopicList(topics, nullptr));
  }
  throw InputError(
      path + ": " + std::to_string(clouds) +
      " PointCloud2 topics, choose one with --topic: " + TopicList(topics, IsPointCloud2Type));
}

void ValidateSelection(const BagScanSelection& s) {
  const auto require = [](double value, const char* what) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      throw InputError(std::string(what) + ": must be a number of seconds >= 0");
    }
  };
  require(s.start, "start");
  require(s.duration, "duration");
  require(s.min_interval, "min interval");
}

int64_t Nanoseconds(double seconds) {
  return static_cast<int64_t>(std::llround(seconds * kNanosecondsPerSecond));
}

// The messages inside the window, thinned to min_interval.
std::vector<BagMessageRef> MessagesInWindow(const std::vector<BagMessageRef>& messages,
                                            int64_t bag_start_ns, const BagScanSelection& s) {
  const int64_t from = bag_start_ns + Nanoseconds(s.start);
  const int64_t to = s.duration > 0.0 ? from + Nanoseconds(s.duration) : INT64_MAX;
  const int64_t interval = Nanoseconds(s.min_interval);
  std::vector<BagMessageRef> kept;
  for (const BagMessageRef& message : messages) {
    if (message.log_time_ns < from || message.log_time_ns >= to) continue;
    if (!kept.empty() && message.log_time_ns - kept.back().log_time_ns < interval) continue;
    kept.push_back(message);
  }
  return kept;
}

// Every pose of `topic`, sorted by header stamp.
std::vector<StampedPose> ReadPoses(BagReader& bag, const BagTopic& topic) {
  std::vector<StampedPose> poses;
  for (const BagMessageRef& message : bag.Messages(topic.name)) {
    const std::vector<uint8_t> data = bag.Read(message);
    poses.push_back(DecodePoseMessage(
        data.data(), data.size(), bag.encoding(), topic.type,
        bag.path() + ": " + topic.name + " message " + std::to_string(poses.size())));
  }
  std::stable_sort(poses.begin(), poses.end(), [](const StampedPose& a, const StampedPose& b) {
    return a.stamp_ns < b.stamp_ns;
  });
  return poses;
}

// Every transform of the bag's /tf_static topic, in log order; none when it
// has no such topic.
std::vector<FrameTransform> ReadStaticTransforms(BagReader& bag,
                                                 const std::vector<BagTopic>& topics) {
  std::vector<FrameTransform> transforms;
  const BagTopic* topic = FindTopic(topics, "/tf_static");
  if (topic == nullptr || !IsTfMessageType(topic->type)) return transforms;
  for (const BagMessageRef& message : bag.Messages(topic->name)) {
    const std::vector<uint8_t> data = bag.Read(message);
    const std::vector<FrameTransform> some =
        DecodeTfMessage(data.data(), data.size(), bag.encoding(),
                        bag.path() + ": " + topic->name + " message at " +
                            std::to_string(message.log_time_ns) + " ns");
    transforms.insert(transforms.end(), some.begin(), some.end());
  }
  return transforms;
}

// Where the scans' sensor sits on the body frame the odometry tracks
// (T_body_sensor), and what the user is told about it.
struct Extrinsic {
  Transform body_sensor = Transform::Identity();
  std::string note;
};

Extrinsic FindExtrinsic(BagReader& bag, const std::vector<BagTopic>& topics,
                        const std::string& body, const std::string& sensor) {
  Extrinsic extrinsic;
  if (body.empty() || sensor.empty()) {
    extrinsic.note = "; its poses are taken as the sensor's (no body or sensor frame named)";
    return extrinsic;
  }
  std::optional<Transform> found;
  try {
    found = TransformBetween(ReadStaticTransforms(bag, topics), body, sensor);
  } catch (const InputError& e) {
    throw InputError(bag.path() + ": /tf_static: " + e.what());
  }
  if (!found) {
    extrinsic.note = "; no /tf_static path from " + body + " to " + sensor +
                     ": its poses are taken as the sensor's";
    return extrinsic;
  }
  extrinsic.body_sensor = *found;
  if (!found->isIdentity()) extrinsic.note = "; " + sensor + " on " + body + " from /tf_static";
  return extrinsic;
}

}  // namespace

bool BagScanSelection::Any() const {
  return !topic.empty() || !odometry_topic.empty() || start != 0.0 || duration != 0.0 ||
         min_interval != 0.0;
}

std::optional<Transform> InterpolatePose(const std::vector<StampedPose>& poses, int64_t stamp_ns) {
  const auto after = std::lower_bound(
      poses.begin(), poses.end(), stamp_ns,
      [](const StampedPose& pose, int64_t stamp) { return pose.stamp_ns < stamp; });
  if (after != poses.end() && after->stamp_ns == stamp_ns) return after->pose;
  if (after == poses.begin() || after == poses.end()) return std::nullopt;
  const StampedPose& a = *std::prev(after);
  const StampedPose& b = *after;
  const double t =
      static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  const Eigen::Quaterniond qa(a.pose.topLeftCorner<3, 3>());
  const Eigen::Quaterniond qb(b.pose.topLeftCorner<3, 3>());
  Transform pose = Transform::Identity();
  pose.topLeftCorner<3, 3>() = qa.slerp(t, qb).toRotationMatrix();
  pose.topRightCorner<3, 1>() =
      (1.0 - t) * a.pose.topRightCorner<3, 1>() + t * b.pose.topRightCorner<3, 1>();
  return pose;
}

namespace io_detail {

FullListing ListBagScans(const std::string& path, const BagScanSelection& selection) {
  ValidateSelection(selection);
  const std::unique_ptr<BagReader> bag = OpenBag(path);
  const std::vector<BagTopic> topics = bag->Topics();
  const BagTopic& scan_topic = ScanTopic(path, topics, selection.topic);
  const std::vector<BagMessageRef> messages =
      MessagesInWindow(bag->Messages(scan_topic.name), bag->TimeRange().first, selection);
  if (messages.empty()) {
    throw InputError(path + ": no " + scan_topic.name + " message inside the window (start " +
                     std::to_string(selection.start) + " s, duration " +
                     std::to_string(selection.duration) + " s)");
  }
  std::vector<StampedPose> poses;
  if (!selection.odometry_topic.empty()) {
    poses = ReadPoses(*bag, RequireTopic(path, topics, selection.odometry_topic, IsPoseMessageType,
                                         "Odometry or PoseStamped"));
  }

  FullListing out;
  std::vector<int64_t> stamps;
  std::string sensor_frame;
  for (const BagMessageRef& message : messages) {
    const std::vector<uint8_t> data = bag->Read(message);
    const std::string what =
        bag->path() + ": " + scan_topic.name + " message " + std::to_string(out.scans.size());
    const PointCloud2Info info = PeekPointCloud2(data.data(), data.size(), bag->encoding(), what);
    if (sensor_frame.empty()) sensor_frame = info.frame_id;
    // A driver that leaves the stamp at zero has only the log time to give.
    stamps.push_back(info.stamp_ns != 0 ? info.stamp_ns : message.log_time_ns);
    ScanSource scan;
    scan.path = bag->path();
    scan.load.format = CloudFormat::kRosMessage;
    scan.load.bag_message = message;
    scan.timestamp = static_cast<double>(stamps.back()) / kNanosecondsPerSecond;
    out.scans.push_back(std::move(scan));
  }
  out.what = BagStorageName(bag->storage()) + ", " + scan_topic.name;
  if (selection.odometry_topic.empty()) return out;
  int with_prior = 0;
  Extrinsic extrinsic;
  if (!poses.empty()) {
    // The odometry tracks its body frame; a prior is where the sensor was.
    extrinsic = FindExtrinsic(*bag, topics, poses.front().child_frame_id, sensor_frame);
    for (const int64_t stamp : stamps) {
      std::optional<Transform> pose = InterpolatePose(poses, stamp);
      if (pose) pose = Transform(*pose * extrinsic.body_sensor);
      with_prior += pose.has_value();
      out.reference_poses.push_back(pose);
    }
  }
  out.what += "; " + selection.odometry_topic + " gives priors to " + std::to_string(with_prior) +
              " of them" + extrinsic.note;
  return out;
}

}  // namespace io_detail
}  // namespace boicp
