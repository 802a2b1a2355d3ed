// What the proxy page computed in the browser (web/page-test.mjs wrote it) against the runtime
// header and the tools: the counts on <body> are the .spx's; every sphere the page showed is
// the one blend_global_xyzr, blend_local_normalized, blend_morph_xyzr or skin gives for the page's
// own inputs (its weights, painted site weights, morph weights, joint matrices), within float
// rounding; the page's max error as opened is the vertex-to-union distance the tools measure (the
// rest mesh against the rest spheres, or with the asset, or its one mesh, the clip's first frame
// as Asset::at_time poses it), and its joint matrices there are the asset's.
// usage: page_check PROXY.spx RUN.page.json PAGE.html [ASSET [MESH]]
#include <cstdio>
#include <cstring>
#include <string>

#include "core/atomic_file.hpp"
#include "core/base64.hpp"
#include "core/json_io.hpp"
#include "extract/asset.hpp"
#include "mesh/union_distance.hpp"
#include "spx_runtime.h"

using spx::json;

namespace {

int failures = 0;
void expect(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  failures += !ok;
}

std::vector<float> floats(const json& a) { return a.get<std::vector<float>>(); }

// The page's data, as proxy-export wrote it into the page.
json page_data(const std::string& html_path) {
  const std::string html = spx::read_file(html_path);
  const std::string open = "<script type=\"application/json\" id=\"spx-data\">";
  const size_t a = html.find(open), b = html.find("</script>", a);
  if (a == std::string::npos || b == std::string::npos) return nullptr;
  return json::parse(html.substr(a + open.size(), b - a - open.size()));
}

std::vector<float> unpacked(const json& b64) {
  const std::string bytes = spx::decode_base64(b64.get<std::string>()).value();
  std::vector<float> out(bytes.size() / 4);
  std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

double largest_difference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return 1e300;
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, double(std::abs(a[i] - b[i])));
  return d;
}

// The runtime's spheres for the inputs the page used in `sample`.
std::vector<float> runtime_spheres(const spx::Proxy& proxy, const json& sample, std::string& how) {
  std::vector<float> out(4 * size_t(proxy.sphere_count()));
  spx::Status s = spx::SPX_ERR_INVALID_ARGUMENT;
  if (sample.contains("weights")) {
    const std::vector<float> w = floats(sample["weights"]);
    s = spx::blend_global_xyzr(proxy, w.data(), uint32_t(w.size()), out.data());
    how = "blend_global_xyzr";
  } else if (sample.contains("morphWeights")) {
    const std::vector<float> w = floats(sample["morphWeights"]);
    s = spx::blend_morph_xyzr(proxy, w.data(), uint32_t(w.size()), out.data());
    how = "blend_morph_xyzr";
  } else if (sample.contains("siteWeights")) {
    const std::vector<float> w = floats(sample["siteWeights"]);
    std::vector<float> normalized(w.size());
    s = spx::normalize_site_weights(proxy, w.data(), w.size(), normalized.data());
    if (s == spx::SPX_OK) s = spx::blend_local_normalized(proxy, normalized.data(), w.size(), out.data());
    how = "blend_local_normalized";
  } else if (sample.contains("matrices")) {
    const std::vector<float> m = floats(sample["matrices"]);
    s = spx::skin(proxy, m.data(), int(m.size() / 16), out.data());
    how = "skin";
  }
  if (s != spx::SPX_OK) how += std::string(" failed: ") + spx::status_string(s);
  return out;
}

// The tools' max |vertex-to-union distance| (in % of the diagonal) for what the page opened on.
double opened_max_error(const json& data, const std::vector<float>& xyzr, const std::string& asset,
                        const std::string& mesh, const json& opened) {
  spx::SphereSet spheres;
  for (size_t j = 0; j + 3 < xyzr.size(); j += 4)
    spheres.push_back({Eigen::Vector3d(xyzr[j], xyzr[j + 1], xyzr[j + 2]), double(xyzr[j + 3])});
  std::vector<Eigen::Vector3d> vertices;
  if (asset.empty()) {
    const std::vector<float> rest = unpacked(data["body"]["poses"][0]);
    for (size_t i = 0; i + 2 < rest.size(); i += 3) vertices.emplace_back(rest[i], rest[i + 1], rest[i + 2]);
  } else {
    const spx::Asset rig(asset, mesh);
    const spx::WeldedBody body = spx::weld_body(rig);
    size_t opened_points = 0;
    vertices = spx::welded_pose(body, rig.at_time(0, 0.0), 1e-6, opened_points, "frame 0", asset).vertices;
    const std::vector<size_t> joint = rig.joints_named(data["skin"]["joints"].get<std::vector<std::string>>());
    const std::vector<Eigen::Matrix4d> m = rig.joint_matrices(0, 0.0);
    const std::vector<float> shown = floats(opened["matrices"]);
    double d = 0;
    for (size_t j = 0; j < joint.size(); ++j)
      for (int k = 0; k < 16; ++k) d = std::max(d, std::abs(double(shown[16 * j + size_t(k)]) - m[joint[j]](k % 4, k / 4)));
    expect(d < 1e-5, "the page's joint matrices at frame 0 are the asset's (" + std::to_string(d) + ")");
  }
  return 100 * spx::summarize_abs(spx::union_signed_distance(vertices, spheres)).max /
         data["body"]["diagonal"].get<double>();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: page_check PROXY.spx RUN.page.json PAGE.html [ASSET [MESH]]\n");
    return 2;
  }
  spx::Proxy proxy;
  if (spx::load_file(argv[1], &proxy) != spx::SPX_OK) return std::printf("FAIL: cannot load %s\n", argv[1]), 1;
  const json run = json::parse(spx::read_file(argv[2]));
  const json data = page_data(argv[3]);
  const std::string asset = argc > 4 ? argv[4] : "", mesh = argc > 5 ? argv[5] : "";
  const json& shown = run["dataset"];
  expect(shown["spheres"] == std::to_string(proxy.sphere_count()), "data-spheres is the .spx's sphere count");
  expect(shown["poses"] == std::to_string(proxy.pose_count()), "data-poses is the .spx's pose count");
  expect(shown["joints"] == std::to_string(proxy.has_skin() ? proxy.joint_count() : 0), "data-joints is the .spx's joint count");
  double extent = 0;
  for (uint32_t j = 0; j < 4 * proxy.sphere_count(); ++j) extent = std::max(extent, double(std::abs(proxy.pose_spheres(0)[j])));
  for (const json& sample : run["samples"]) {
    std::string how;
    const double d = largest_difference(floats(sample["xyzr"]), runtime_spheres(proxy, sample, how));
    expect(d <= 1e-5 * std::max(extent, 1.0), sample["what"].get<std::string>() + ": the page's spheres are the runtime's " +
                                                 how + " (largest difference " + std::to_string(d) + ")");
  }
  if (data.is_null()) expect(false, std::string(argv[3]) + " holds no page data");
  else if (!data["body"].is_null()) {
    const json& opened = run["samples"][0];
    const double tools = opened_max_error(data, floats(opened["xyzr"]), asset, mesh, opened);
    const double page = std::stod(shown["maxError"].get<std::string>());
    expect(std::abs(tools - page) <= 1e-4 * std::max(tools, 1.0),
           "data-max-error as opened (" + std::to_string(page) + " %) is the tools' measure (" + std::to_string(tools) + " %)");
  }
  std::printf("page_check: %d failed\n", failures);
  return failures ? 1 : 0;
}
