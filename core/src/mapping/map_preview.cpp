#include "boicp/mapping/map_preview.hpp"

#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <string>

#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>

#include "boicp/util/atomic_file.hpp"
#include "boicp/util/percentile.hpp"
#include "mapping/octree_file.hpp"

namespace boicp {
namespace {

using Rgb = std::array<uint8_t, 3>;

constexpr Rgb kBackground{24, 24, 28};
constexpr Rgb kTrajectory{255, 255, 255};
constexpr Rgb kStart{40, 220, 60};
constexpr Rgb kEnd{235, 40, 40};

OccupiedCells CollectOccupied(octomap::OcTree& tree) {
  OccupiedCells cells;
  cells.resolution = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    cells.centres.emplace_back(c.x(), c.y(), c.z());
    cells.sizes.push_back(it.getSize());
  }
  return cells;
}

// Google's polynomial approximation of the turbo colour map, t in [0, 1].
// Its darkest ends are cut off so that no height fades into the background.
Rgb Turbo(double t) {
  t = 0.1 + 0.85 * std::clamp(t, 0.0, 1.0);
  const double r =
      0.13572138 +
      t * (4.61539260 +
           t * (-42.66032258 + t * (132.13108234 + t * (-152.94239396 + t * 59.28637943))));
  const double g =
      0.09140261 +
      t * (2.19418839 + t * (4.84296658 + t * (-14.18503333 + t * (4.27729857 + t * 2.82956604))));
  const double b =
      0.10667330 +
      t * (12.64194608 +
           t * (-60.58204836 + t * (110.36276771 + t * (-89.90310912 + t * 27.34824973))));
  auto byte = [](double v) {
    return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255));
  };
  return {byte(r), byte(g), byte(b)};
}

class Canvas {
 public:
  Canvas(int width, int height) : image_{width, height, {}} {
    image_.pixels.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
    Fill(0, 0, width, height, kBackground);
  }
  void Set(int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= image_.width || y >= image_.height) return;
    const size_t i =
        (static_cast<size_t>(y) * static_cast<size_t>(image_.width) + static_cast<size_t>(x)) * 3;
    std::copy(c.begin(), c.end(), image_.pixels.begin() + static_cast<std::ptrdiff_t>(i));
  }
  void Fill(int x0, int y0, int x1, int y1, const Rgb& c) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) Set(x, y, c);
    }
  }
  // Bresenham, `thickness` pixels wide.
  void Line(int x0, int y0, int x1, int y1, int thickness, const Rgb& c) {
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
      Fill(x0 - thickness / 2, y0 - thickness / 2, x0 + (thickness + 1) / 2,
           y0 + (thickness + 1) / 2, c);
      if (x0 == x1 && y0 == y1) return;
      const int e2 = 2 * err;
      if (e2 >= dy) err += dy, x0 += sx;
      if (e2 <= dx) err += dx, y0 += sy;
    }
  }
  RgbImage Take() { return std::move(image_); }

 private:
  RgbImage image_;
};

// Rows: the picture's right, its top and `up` (map frame). The right is the
// map's x laid flat (its y when x is along up), so up = z is the identity.
Eigen::Matrix3d ViewRotation(const Eigen::Vector3d& up_in) {
  const Eigen::Vector3d up = up_in.normalized();
  Eigen::Vector3d right = Eigen::Vector3d::UnitX() - up.x() * up;
  if (right.norm() < 1e-3) right = Eigen::Vector3d::UnitY() - up.y() * up;
  right.normalize();
  Eigen::Matrix3d rotation;
  rotation.row(0) = right.transpose();
  rotation.row(1) = up.cross(right).transpose();
  rotation.row(2) = up.transpose();
  return rotation;
}

}  // namespace

OccupiedCells ReadOccupiedCells(const std::string& path) {
  return CollectOccupied(*ReadOctreeFile(path));
}

RgbImage RenderTopDown(const OccupiedCells& cells, const Points& trajectory,
                       const PreviewOptions& options) {
  if (options.size_px < 64) throw InputError("preview size: must be >= 64 pixels");
  if (cells.centres.empty() && trajectory.empty()) {
    throw InputError("preview: the map has no occupied cells and there is no trajectory");
  }
  if (!(options.up.norm() > 0.0)) throw InputError("preview: the up direction is zero");
  // Everything in view coordinates: x right, y towards the top, z = height.
  const Eigen::Matrix3d view = ViewRotation(options.up);
  // A cube's shadow on the picture's axes: half an edge times the L1 norm
  // of each axis in the map frame.
  const Eigen::Vector2d shadow(view.row(0).cwiseAbs().sum(), view.row(1).cwiseAbs().sum());
  Points centres, path;
  std::vector<Eigen::Vector2d> halves;
  for (size_t i = 0; i < cells.centres.size(); ++i) {
    centres.push_back(view * cells.centres[i]);
    halves.push_back(shadow * cells.sizes[i] / 2);
  }
  for (const Point& p : trajectory) path.push_back(view * p);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (size_t i = 0; i < centres.size(); ++i) {
    lo = lo.cwiseMin(centres[i].head<2>() - halves[i]);
    hi = hi.cwiseMax(centres[i].head<2>() + halves[i]);
  }
  for (const Point& p : path) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-3);
  // The map gets the longer side minus a margin and the colour bar's strip.
  const int margin = options.size_px / 40 + 4, bar = options.size_px / 32 + 6;
  const int room = options.size_px - 2 * margin - bar - margin;
  const double scale = room / extent.maxCoeff();
  // extent * (room / extent) may round to a hair above room.
  const int map_w = std::min(room, static_cast<int>(std::ceil(extent.x() * scale)));
  const int map_h = std::min(room, static_cast<int>(std::ceil(extent.y() * scale)));
  const int width = map_w + 3 * margin + bar;
  const int height = std::max(map_h, 64) + 2 * margin;
  Canvas canvas(width, height);
  auto column = [&](double x) {
    return margin + static_cast<int>(std::floor((x - lo.x()) * scale));
  };
  auto row = [&](double y) {
    return height - margin - 1 - static_cast<int>(std::floor((y - lo.y()) * scale));
  };

  if (!centres.empty()) {
    std::vector<double> heights;
    for (const Point& c : centres) heights.push_back(c.z());
    const double z_lo = Percentile(heights, 0.02), z_hi = Percentile(heights, 0.98);
    const double z_span = std::max(z_hi - z_lo, 1e-6);
    // Lower cells first, so that the highest one at each spot is the one seen.
    std::vector<size_t> order(centres.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return centres[a].z() < centres[b].z(); });
    for (size_t i : order) {
      const Point& c = centres[i];
      const double hx = halves[i].x(), hy = halves[i].y();
      const Rgb colour = Turbo((c.z() - z_lo) / z_span);
      canvas.Fill(column(c.x() - hx), row(c.y() + hy),
                  std::max(column(c.x() + hx), column(c.x() - hx) + 1),
                  std::max(row(c.y() - hy), row(c.y() + hy) + 1), colour);
    }
  }
  // Colour bar: low heights at the bottom.
  const int bar_x = width - margin - bar, bar_top = margin, bar_bottom = height - margin;
  for (int y = bar_top; y < bar_bottom; ++y) {
    const double t = 1.0 - static_cast<double>(y - bar_top) / std::max(bar_bottom - bar_top - 1, 1);
    canvas.Fill(bar_x, y, bar_x + bar, y + 1, Turbo(t));
  }

  const int thickness = std::max(2, options.size_px / 400);
  for (size_t i = 1; i < path.size(); ++i) {
    canvas.Line(column(path[i - 1].x()), row(path[i - 1].y()), column(path[i].x()),
                row(path[i].y()), thickness, kTrajectory);
  }
  if (!path.empty()) {
    const int mark = std::max(4, options.size_px / 100);
    auto square = [&](const Point& p, const Rgb& c) {
      canvas.Fill(column(p.x()) - mark, row(p.y()) - mark, column(p.x()) + mark + 1,
                  row(p.y()) + mark + 1, c);
    };
    square(path.front(), kStart);
    square(path.back(), kEnd);
  }
  return canvas.Take();
}

void WritePng(const std::string& path, const RgbImage& image) {
  open3d::geometry::Image o3d;
  o3d.Prepare(image.width, image.height, 3, 1);
  std::memcpy(o3d.data_.data(), image.pixels.data(), image.pixels.size());
  WriteFileAtomically(path, [&](const std::string& tmp) {
    // WriteImageToPNG, not WriteImage: the temporary name has no .png extension.
    if (!open3d::io::WriteImageToPNG(tmp, o3d))
      throw std::runtime_error(path + ": cannot write PNG");
  });
}

UpDirection WriteMapPreview(const std::string& octomap_path, const std::vector<Transform>& poses,
                            const std::string& png_path, const PreviewOptions& options,
                            const UpDetectionOptions& up_options) {
  Points trajectory;
  for (const Transform& T : poses) trajectory.push_back(T.block<3, 1>(0, 3));
  const OccupiedCells cells = ReadOccupiedCells(octomap_path);
  const UpDirection up = DetectUp(cells.centres, cells.sizes, cells.resolution, poses, up_options);
  PreviewOptions along_up = options;
  along_up.up = up.up;
  WritePng(png_path, RenderTopDown(cells, trajectory, along_up));
  return up;
}

}  // namespace boicp
