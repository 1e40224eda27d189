// Uploads whose headers declare far more points than --max-scan-points, or
// fewer points than the limit but far more bytes than the file holds: the
// daemon refuses each from its header, before allocating the points, and
// stays small and up.

#include <iostream>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "../support/memory_bombs.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

using ::testing::HasSubstr;

constexpr uint64_t kPeakRssLimitMb = 300;

v1::ScanFormat FormatOf(const std::string& file_name) {
  const std::string extension = std::filesystem::path(file_name).extension().string();
  if (extension == ".pcd") return v1::SCAN_FORMAT_PCD;
  if (extension == ".ply") return v1::SCAN_FORMAT_PLY;
  if (extension == ".png") return v1::SCAN_FORMAT_DEPTH_PNG;
  if (extension == ".bin") return v1::SCAN_FORMAT_KITTI_BIN;
  return v1::SCAN_FORMAT_XYZ;
}

class MemoryBombs : public ServerTest {};

TEST_F(MemoryBombs, EachIsRefusedFromItsHeaderAndTheDaemonStaysSmall) {
  const std::vector<MemoryBomb> bombs = WriteMemoryBombs(dir_);
  StartDaemon({"--workers", "1"});
  auto client = Client();
  for (const MemoryBomb& bomb : bombs) {
    const std::string bytes = Slurp(dir_ / bomb.file_name);
    v1::ScanMetadata meta = Meta(FormatOf(bomb.file_name), 0);
    if (meta.format() == v1::SCAN_FORMAT_DEPTH_PNG) {
      v1::DepthCamera& depth = *meta.mutable_depth();
      depth.set_fx(500.0);
      depth.set_fy(500.0);
      depth.set_cx(4096.0);
      depth.set_cy(4096.0);
      depth.set_depth_scale(1000.0);
    }
    const grpc::Status status = StatusOf([&] { client.Upload(bytes, meta); });
    const uint64_t peak_mb = PeakRssMb(daemon_->pid());
    std::cout << bomb.name << " (" << bytes.size() << " bytes, " << bomb.declared_points
              << " points declared): " << status.error_code() << " '" << status.error_message()
              << "', daemon peak RSS " << peak_mb << " MB\n";
    if (bomb.refusal.empty()) {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << bomb.name;
      EXPECT_THAT(status.error_message(),
                  HasSubstr("over this daemon's limit of 5000000 (--max-scan-points)"))
          << bomb.name;
    } else {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << bomb.name;
      EXPECT_THAT(status.error_message(), HasSubstr(bomb.refusal)) << bomb.name;
    }
    EXPECT_LT(peak_mb, kPeakRssLimitMb) << bomb.name;
    ASSERT_EQ(daemon_->Wait(0.1), -1) << "the daemon exited on " << bomb.name;
  }
}

}  // namespace
}  // namespace boicp::test
