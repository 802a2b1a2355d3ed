#pragma once
// The error of a proxy over a clip as a picture (the paper's Figure 5): per frame the max vertex
// error and the union's overshoot of each runtime, in % of the rest diagonal, as an SVG.
#include <string>

#include "metrics/motion_eval.hpp"

namespace spx {

// `tolerance` <= 0 draws no target line.
std::string motion_chart_svg(const MotionResult& result, double diagonal, double tolerance, const std::string& title);

}  // namespace spx
