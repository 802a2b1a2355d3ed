#pragma once
// A line per pose on the terminal. A whole clip's frames (hundreds) would bury the warnings above
// them, so past kAllPoseLines poses only the first (the rest pose) and the worst few are printed,
// with a line saying how many were left out and where every one is; -v prints them all.
#include <cstddef>
#include <string>
#include <vector>

#include "core/log.hpp"

namespace spx {

struct PoseLine {
  std::string text;
  double worst = 0;  // the larger, the worse (the pose's max error, say)
};

constexpr size_t kAllPoseLines = 12;  // more poses than this print the worst kWorstPoseLines
constexpr size_t kWorstPoseLines = 5;

// The width of the name column over `poses` (anything with a `name`), at least 12: padded to the
// longest so that the figures after them line up (a clip's times differ in width).
template <class Poses>
int pose_name_width(const Poses& poses) {
  size_t width = 12;
  for (const auto& pose : poses) width = pose.name.size() > width ? pose.name.size() : width;
  return static_cast<int>(width);
}

// Which of `lines` are printed (indices, ascending): all of them when there are at most
// kAllPoseLines or `every`; else the first and the kWorstPoseLines worst of the others (ties: the
// earlier pose).
std::vector<size_t> pose_lines_shown(const std::vector<PoseLine>& lines, bool every);

// Prints pose_lines_shown(lines, -v) by log.info, each indented by `indent`, and where some were
// left out a line saying how many and where every one is.
void print_pose_lines(const std::vector<PoseLine>& lines, const Log& log, const std::string& indent);

}  // namespace spx
