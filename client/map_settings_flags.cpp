#include "map_settings_flags.hpp"

namespace boicp::cli {

void AddMapSettingsFlags(CLI::App& app, MapSettingsFlags& flags) {
  MapSettings& s = flags.settings;
  app.add_option("PATH", s.path, "Scan folder (KITTI, TUM, 7-Scenes, or .pcd/.ply/.xyz files)");
  app.add_option("--layout", s.layout, "auto, kitti, tum, 7scenes or files")->capture_default_str();
  app.add_option("--config", s.preset, "BO-ICP preset A, B or C")->capture_default_str();
  app.add_option("--pairing", flags.pairing_words,
                 "consecutive, overlap (keyframes by overlap) or explicit FILE (lines of "
                 "'source,target' scan indices)")
      ->expected(1, -1)
      ->default_str("consecutive");
  app.add_option("--mode", s.mode, "nested (rotation then translation) or 6dof")
      ->capture_default_str();
  app.add_option("--resolution", s.resolution, "OctoMap leaf size (m); default: from the scans");
  app.add_option("--max-range", s.max_range,
                 "OctoMap ray length (m), 0 = no limit; default: from the scans");
  app.add_option("--voxel", s.voxel, "Search voxel (m); default: from the scans");
  app.add_option("--random-samples", s.random_samples,
                 "N_r per search stage; default: the preset's");
  app.add_option("--iterations", s.iterations, "N per search stage; default: the preset's");
  app.add_option("--rotation-bounds", s.rotation_bounds,
                 "Half-widths roll,pitch,yaw (rad, or pi); default: from the sensor");
  app.add_option("--translation-bounds", s.translation_bounds,
                 "Half-widths x,y,z (m); default: from the scans");
  app.add_flag("--fixed-settings", s.fixed_settings,
               "The preset's fixed voxel, bounds and map settings instead of choosing them");
  app.add_flag("--no-retry", s.no_retry, "Never search a doubtful pair again");
  app.add_option("--seed", s.seed, "Job seed; each pair's seed derives from it")
      ->capture_default_str();
  app.add_option("--first", s.first, "Index of the first scan kept")->capture_default_str();
  app.add_option("--stride", s.stride, "Keep every N-th scan")->capture_default_str();
  app.add_option("--count", s.count, "At most N scans; 0 = all")->capture_default_str();
  app.add_option("--intrinsics", s.intrinsics, "Depth camera fx,fy,cx,cy (pixels)");
  app.add_option("--depth-scale", s.depth_scale,
                 "Raw depth units per metre; 0 = the layout's (TUM 5000, 7-Scenes 1000)");
  app.add_option("--camera", s.camera, "TUM camera fr1, fr2 or fr3");
  app.add_flag("--poses-as-priors", s.poses_as_priors,
               "Use the folder's poses (KITTI poses.txt, 7-Scenes) as search priors");
}

MapSettings ResolveMapSettings(const MapSettingsFlags& flags) {
  MapSettings s = flags.settings;
  std::vector<std::string> words = flags.pairing_words;
  if (words.empty()) words = {"consecutive"};
  s.pairing = words[0];
  size_t used = 1;
  if (s.pairing == "explicit" && words.size() > 1) s.pairs_file = words[used++];
  if (words.size() > used) {
    if (!s.path.empty() || words.size() > used + 1) {
      throw InputError("--pairing: unexpected '" + words[used] +
                       "' (consecutive, overlap or explicit FILE)");
    }
    s.path = words[used];
  }
  if (s.path.empty()) throw InputError("PATH: the folder of scans is required");
  return s;
}

}  // namespace boicp::cli
