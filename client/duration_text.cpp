#include "duration_text.hpp"

#include <cmath>
#include <cstdio>

namespace boicp::cli {

std::string FormatDuration(double seconds) {
  if (!(seconds >= 0.0)) return "?";
  const long total = std::lround(seconds);
  char text[32];
  if (total >= 3600) {
    std::snprintf(text, sizeof text, "%ldh%02ldm", total / 3600, total % 3600 / 60);
  } else if (total >= 60) {
    std::snprintf(text, sizeof text, "%ldm%02lds", total / 60, total % 60);
  } else {
    std::snprintf(text, sizeof text, "%lds", total);
  }
  return text;
}

}  // namespace boicp::cli
