#include "map_settings_flags.hpp"

#include "boicp/util/system_memory.hpp"

namespace boicp::cli {
namespace {

void AddBagFlags(CLI::App& app, BagScanSelection& bag) {
  app.add_option("--topic", bag.topic,
                 "Bag: the PointCloud2 topic of the scans (default: the bag's only one)");
  app.add_option("--odometry-topic", bag.odometry_topic,
                 "Bag: an Odometry or PoseStamped topic whose pose at each scan's stamp is its "
                 "prior");
  app.add_option("--start", bag.start, "Bag: seconds after its first message to start at")
      ->capture_default_str();
  app.add_option("--duration", bag.duration, "Bag: seconds of scans kept; 0 = to the end")
      ->capture_default_str();
  app.add_option("--min-interval", bag.min_interval,
                 "Bag: seconds at least between kept scans (instead of --every)")
      ->capture_default_str();
}

}  // namespace

void AddFusionLimitFlag(CLI::App& app, uint64_t& max_fusion_mb) {
  max_fusion_mb = DefaultFusionLimitMb();
  app.add_option("--max-fusion-mb", max_fusion_mb,
                 "MiB the map's fusion may hold (default: half the memory of this machine or "
                 "container); a map estimated over it is refused before any pair is "
                 "registered, and one that grows past it stops (0 = no limit)")
      ->capture_default_str();
}

void AddMapSettingsFlags(CLI::App& app, MapSettingsFlags& flags, settings::Frontend frontend) {
  MapSettings& s = flags.settings;
  flags.frontend = frontend;
  app.add_option("PATH", flags.paths,
                 "Scan folder (KITTI, TUM, 7-Scenes, or .pcd/.ply/.xyz files) or bag (ROS 1 "
                 ".bag, ROS 2 .mcap, .db3 or bag folder); several: drives of one place, "
                 "mapped into the first's frame");
  app.add_option("--layout", s.layout, "auto, kitti, tum, 7scenes, files or bag")
      ->capture_default_str();
  app.add_option("--pairing", flags.pairing_words,
                 "consecutive, overlap (keyframes by overlap) or explicit FILE (lines of "
                 "'source,target' scan indices)")
      ->expected(1, -1)
      ->default_str("consecutive");
  app.add_option("--overlap-threshold", s.overlap_threshold,
                 "Overlap pairing: a scan that overlaps the current keyframe by less starts the "
                 "next keyframe, in (0, 1]; 0 = 0.6 for depth images, 0.7 otherwise")
      ->capture_default_str();
  app.add_option("--extra-pairs", s.extra_pairs_file,
                 "Consecutive or overlap pairing: FILE of 'source,target' scan indices "
                 "registered besides (loop closures, weighed in a pose graph)");
  settings::AddSettingFlags(app, frontend, s, flags.setting_texts);
  app.add_option("--first", s.first, "Index of the first scan kept")->capture_default_str();
  app.add_option("--stride,--every", s.stride, "Keep every N-th scan")->capture_default_str();
  app.add_option("--count", s.count, "At most N scans; 0 = all")->capture_default_str();
  app.add_option("--intrinsics", s.intrinsics, "Depth camera fx,fy,cx,cy (pixels)");
  app.add_option("--depth-scale", s.depth_scale,
                 "Raw depth units per metre; 0 = the layout's (TUM 5000, 7-Scenes 1000)");
  app.add_option("--camera", s.camera, "TUM camera fr1, fr2 or fr3");
  app.add_flag("--poses-as-priors", s.poses_as_priors,
               "Use the folder's poses (KITTI poses.txt, 7-Scenes) as search priors");
  AddBagFlags(app, s.bag);
}

MapSettings ResolveMapSettings(const MapSettingsFlags& flags) {
  MapSettings s = flags.settings;
  settings::ApplyFlagTexts(flags.setting_texts, flags.frontend, s);
  std::vector<std::string> words = flags.pairing_words;
  if (words.empty()) words = {"consecutive"};
  s.pairing = words[0];
  size_t used = 1;
  if (s.pairing == "explicit" && words.size() > 1) s.pairs_file = words[used++];
  std::vector<std::string> paths = flags.paths;
  if (words.size() > used) {
    if (!paths.empty()) {
      throw InputError("--pairing: unexpected '" + words[used] +
                       "' (consecutive, overlap or explicit FILE)");
    }
    paths.assign(words.begin() + static_cast<std::ptrdiff_t>(used), words.end());
  }
  if (paths.empty()) throw InputError("PATH: the folder of scans is required");
  s.path = paths.front();
  s.more_paths.assign(paths.begin() + 1, paths.end());
  if (s.stride != 1 && s.bag.min_interval > 0.0) {
    throw InputError("--every and --min-interval: give one of them");
  }
  return s;
}

}  // namespace boicp::cli
