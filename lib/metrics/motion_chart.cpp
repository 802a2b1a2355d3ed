#include "metrics/motion_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace spx {
namespace {

constexpr double kWidth = 900, kLeft = 70, kRight = 20, kPanel = 240, kGap = 60, kTop = 40;
// The host's runtime blue, the other a host could use orange, the best-fit blend grey.
const char* const kColour[kMotionRuntimes] = {"#1f77b4", "#ff7f0e", "#7f7f7f", "#1f77b4", "#ff7f0e"};
const char* const kLabel[kMotionRuntimes] = {"skinned (spx::skin)", "rigid per bone", "best-fit blend of the examples",
                                             "morph blend (spx::blend_morph)", "global blend, rest at 1 - sum"};

// A round step giving about 5 ticks up to `top` (positive and finite: the panels make it so).
double tick_step(double top) {
  const double raw = top / 5, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

struct Panel {
  double y0, t0, t1, top;  // pixel top; time range; value range [0, top]
  double x(double t) const { return kLeft + (t - t0) / std::max(t1 - t0, 1e-12) * (kWidth - kLeft - kRight); }
  double y(double v) const { return y0 + kPanel - std::min(v, top) / top * kPanel; }
};

void axes(std::ostringstream& s, const Panel& p, const char* label) {
  char b[256];
  const double step = tick_step(p.top);
  for (double v = 0; v <= p.top + 1e-12; v += step) {
    std::snprintf(b, sizeof b, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#ddd'/><text x='%g' y='%g' text-anchor='end'>%g</text>\n",
                  kLeft, p.y(v), kWidth - kRight, p.y(v), kLeft - 6, p.y(v) + 4, v);
    s << b;
  }
  const double tstep = tick_step(p.t1 - p.t0);
  for (double t = std::ceil(p.t0 / tstep) * tstep; t <= p.t1 + 1e-12; t += tstep) {
    std::snprintf(b, sizeof b, "<text x='%g' y='%g' text-anchor='middle'>%g</text>\n", p.x(t), p.y0 + kPanel + 16, t);
    s << b;
  }
  std::snprintf(b, sizeof b, "<rect x='%g' y='%g' width='%g' height='%g' fill='none' stroke='#444'/>"
                "<text x='%g' y='%g' font-weight='bold'>%s</text>\n",
                kLeft, p.y0, kWidth - kLeft - kRight, kPanel, kLeft, p.y0 - 8, label);
  s << b;
}

void series(std::ostringstream& s, const Panel& p, const MotionResult& r, int runtime, double scale, bool overshoot) {
  s << "<polyline fill='none' stroke-width='1.5' stroke='" << kColour[runtime] << "' points='";
  char b[64];
  for (const MotionRow& row : r.rows) {
    const FrameError& e = row.error[size_t(runtime)];
    const double v = scale * (overshoot ? e.overshoot : e.max);
    if (!std::isfinite(v)) continue;  // no point for a value not measured
    std::snprintf(b, sizeof b, "%.1f,%.1f ", p.x(row.time), p.y(v));
    s << b;
  }
  s << "'/>\n";
}

void hline(std::ostringstream& s, const Panel& p, double v, const char* dash, const char* text, double text_x) {
  char b[320];
  std::snprintf(b, sizeof b, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#2ca02c' stroke-dasharray='%s'/>"
                "<text x='%g' y='%g' fill='#2ca02c' text-anchor='end'>%s</text>\n",
                kLeft, p.y(v), kWidth - kRight, p.y(v), dash, text_x, p.y(v) - 4, text);
  s << b;
}

}  // namespace

std::string motion_chart_svg(const MotionResult& r, double diagonal, double tolerance, const std::string& title) {
  const double scale = 100 / diagonal;
  double t0 = 0, t1 = 1, worst = tolerance * 1.5 * scale, worst_over = 0.5;
  if (!r.rows.empty()) t0 = r.rows.front().time, t1 = r.rows.back().time;
  const bool blend = r.measured(kBestBlend);
  // The axes fit the host's runtimes; the best-fit blend, far worse between examples, is clipped.
  double blend_worst = 0, blend_worst_over = 0;
  for (const MotionRow& row : r.rows) {
    for (int k : r.runtimes) {
      if (k == kBestBlend) continue;
      worst = std::max(worst, scale * row.error[size_t(k)].max);
      worst_over = std::max(worst_over, scale * row.error[size_t(k)].overshoot);
    }
    blend_worst = std::max(blend_worst, scale * row.error[kBestBlend].max);
    blend_worst_over = std::max(blend_worst_over, scale * row.error[kBestBlend].overshoot);
  }
  // A panel's top and span positive and finite, whatever the values (an axis of NaN or of 0 would
  // never end its ticks).
  const auto usable = [](double v, double fallback) { return v > 0 && std::isfinite(v) ? v : fallback; };
  if (!(t1 - t0 > 0) || !std::isfinite(t1 - t0)) t0 = 0, t1 = 1;
  const Panel error{kTop + 30, t0, t1, usable(worst * 1.05, 1.0)},
      over{kTop + 30 + kPanel + kGap, t0, t1, usable(worst_over * 1.05, 1.0)};
  const double height = over.y0 + kPanel + 70;
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='" << height
    << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n"
    << "<text x='" << kLeft << "' y='22' font-size='15'>" << title << ": " << r.rows.size()
    << " times, error of the proxy's spheres in % of the rest diagonal</text>\n";
  axes(s, error, "max distance from the body's vertices to the union");
  axes(s, over, "overshoot: how far the union may poke out of the body");
  if (tolerance > 0) {
    hline(s, error, scale * tolerance, "6 4", "tolerance", kLeft + 70);
    hline(s, error, 1.25 * scale * tolerance, "2 3", "1.25x tolerance", kWidth - kRight - 4);
  }
  hline(s, over, 0.5, "2 3", "0.5%", kWidth - kRight - 4);
  char note[200];
  if (blend && (blend_worst > error.top || blend_worst_over > over.top)) {
    std::snprintf(note, sizeof note, "best-fit blend clipped: up to %.1f%% error, %.1f%% overshoot", blend_worst,
                  blend_worst_over);
    s << "<text x='" << kLeft << "' y='42' fill='" << kColour[kBestBlend] << "'>" << note
      << "</text>\n";
  }
  for (auto k = r.runtimes.rbegin(); k != r.runtimes.rend(); ++k) {  // the host's drawn last, on top
    series(s, error, r, *k, scale, false);
    series(s, over, r, *k, scale, true);
  }
  const int host = r.runtimes.empty() ? kSkinned : r.runtimes.front();
  for (const MotionRow& row : r.rows)  // the frames the proxy was made from
    if (row.seen)
      s << "<circle cx='" << error.x(row.time) << "' cy='" << error.y(scale * row.error[size_t(host)].max)
        << "' r='2.5' fill='" << kColour[host] << "'/>\n";
  double lx = kLeft;
  for (int k : r.runtimes) {
    s << "<line x1='" << lx << "' y1='" << height - 20 << "' x2='" << lx + 24 << "' y2='" << height - 20
      << "' stroke-width='3' stroke='" << kColour[k] << "'/><text x='" << lx + 30 << "' y='" << height - 16 << "'>"
      << kLabel[k] << "</text>\n";
    lx += 250;
  }
  s << "<text x='" << kWidth / 2 << "' y='" << over.y0 + kPanel + 34
    << "' text-anchor='middle'>time (s); dots: the frames the proxy was made from</text>\n</svg>\n";
  return s.str();
}

}  // namespace spx
