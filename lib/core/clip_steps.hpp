#pragma once
// How often the tools sample a clip between its keys: skin.json's clip (pose-map's check over the
// motion) and a cubic spline's keys made linear (mesh/gltf_input) take the same times.
#include <algorithm>
#include <cmath>

namespace spx {

// Times a second a clip is sampled between keys at least: as often as a host at 60 Hz plays it.
inline constexpr double kClipRate = 60;

// The most steps between two keys (keys 18 minutes apart): a file's key times bound no loop.
inline constexpr int kMostClipSteps = 1 << 16;

// The steps between keys `gap` seconds apart: an even count, so half-way (where hosts and
// proxy-eval look between keys) is one of them, and at least kClipRate a second. Keys 1/30 s
// apart stored as floats are a hair over two 60 Hz steps apart: two steps.
inline int clip_steps_between(double gap) {
  const double wanted = std::ceil(gap * kClipRate - 1e-6);
  if (!(wanted < kMostClipSteps)) return kMostClipSteps;
  const int steps = std::max(2, int(wanted));
  return steps + steps % 2;
}

}  // namespace spx
