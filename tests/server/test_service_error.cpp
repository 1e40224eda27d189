// Replies name files without saying where the daemon keeps them.

#include <gtest/gtest.h>

#include "service_error.hpp"

namespace boicp::server {
namespace {

TEST(WithoutServerPaths, KeepsEachPathsLastNameAndEverythingElse) {
  EXPECT_EQ(WithoutServerPaths("data directory /var/lib/boicpd is not writable: cannot create a "
                               "file in /var/lib/boicpd/scans (Permission denied)"),
            "data directory .../boicpd is not writable: cannot create a file in .../scans "
            "(Permission denied)");
  EXPECT_EQ(WithoutServerPaths("/srv/d/scans/ab/0123.corrupt: moved aside"),
            ".../0123.corrupt: moved aside");
  EXPECT_EQ(WithoutServerPaths("scan 'x' (\"/a/b\")"), "scan 'x' (\".../b\")");
  EXPECT_EQ(WithoutServerPaths("rays of 200 m/s and a/b stay"), "rays of 200 m/s and a/b stay");
  EXPECT_EQ(WithoutServerPaths(""), "");
}

}  // namespace
}  // namespace boicp::server
