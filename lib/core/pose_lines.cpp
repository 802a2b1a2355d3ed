#include "core/pose_lines.hpp"

#include <algorithm>
#include <numeric>

namespace spx {

std::vector<size_t> pose_lines_shown(const std::vector<PoseLine>& lines, bool every) {
  std::vector<size_t> shown(lines.size());
  std::iota(shown.begin(), shown.end(), size_t(0));
  if (every || lines.size() <= kAllPoseLines) return shown;
  std::vector<size_t> others(shown.begin() + 1, shown.end());
  std::stable_sort(others.begin(), others.end(), [&](size_t a, size_t b) { return lines[a].worst > lines[b].worst; });
  others.resize(kWorstPoseLines);
  std::sort(others.begin(), others.end());
  shown.assign(1, 0);
  shown.insert(shown.end(), others.begin(), others.end());
  return shown;
}

void print_pose_lines(const std::vector<PoseLine>& lines, const Log& log, const std::string& indent) {
  const std::vector<size_t> shown = pose_lines_shown(lines, log.verbosity() >= 1);
  for (size_t i = 0; i < shown.size(); ++i) {
    if (i == 1 && shown.size() < lines.size())
      log.info(indent + "the " + std::to_string(shown.size() - 1) + " worst of the other " +
               std::to_string(lines.size() - 1) + " poses (every pose is in the --report JSON; -v prints all):");
    log.info(indent + lines[shown[i]].text);
  }
}

}  // namespace spx
