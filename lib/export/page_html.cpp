#include "export/page_html.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/base64.hpp"
#include "core/error.hpp"
#include "extract/asset.hpp"

namespace spx {

// web/page bundled at build time (page_bundle.cpp, generated; empty without web/node_modules).
extern const char kPageBundle[];
extern const size_t kPageBundleSize;

namespace {

// Arrays go into the page as base64 of little-endian 32-bit values (JavaScript's typed arrays).
template <typename T>
std::string packed(const std::vector<T>& values) {
  static_assert(sizeof(T) == 4, "32-bit values");
  std::string bytes(4 * values.size(), '\0');
  for (size_t i = 0; i < values.size(); ++i) {
    uint32_t v;
    std::memcpy(&v, &values[i], 4);
    for (int b = 0; b < 4; ++b) bytes[4 * i + size_t(b)] = char((v >> (8 * b)) & 0xff);
  }
  return encode_base64(bytes.data(), bytes.size());
}

// Points or triangles as one flat array of T (x y z ..., or a b c ...).
template <typename T, typename V>
std::vector<T> flattened(const std::vector<V>& items) {
  std::vector<T> out;
  out.reserve(3 * items.size());
  for (const V& v : items)
    for (int c = 0; c < 3; ++c) out.push_back(T(v[c]));
  return out;
}
std::vector<float> xyz_of(const std::vector<Eigen::Vector3d>& points) { return flattened<float>(points); }

// The body's rest: its triangles, vertex count, size and diagonal.
json body_frame(const TriMesh& rest) {
  const Eigen::Vector3d size = rest.bounds().sizes();
  return {{"triangles", packed(flattened<uint32_t>(rest.triangles))},
          {"vertex_count", rest.vertices.size()},
          {"size", {size.x(), size.y(), size.z()}},
          {"diagonal", size.norm()}};
}

// Each vertex's nearest blend site (the site whose weights it takes in the local blend).
std::vector<uint32_t> nearest_sites(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Eigen::Vector3d>& sites) {
  std::vector<uint32_t> out(vertices.size(), 0);
  tbb::parallel_for(size_t(0), vertices.size(), [&](size_t v) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t s = 0; s < sites.size(); ++s) {
      const double d = (sites[s] - vertices[v]).squaredNorm();
      if (d < best) best = d, out[v] = uint32_t(s);
    }
  });
  return out;
}

json skin_data(const ProxySkin& skin) {
  std::vector<float> xyzr, weights;
  std::vector<uint32_t> indices;
  for (const SkinnedSphere& s : skin.spheres) {
    for (int c = 0; c < 3; ++c) xyzr.push_back(float(s.center[c]));
    xyzr.push_back(float(s.radius));
    for (size_t k = 0; k < 4; ++k) weights.push_back(s.weight[k]), indices.push_back(uint32_t(s.joint[k]));
  }
  return {{"joints", skin.joints}, {"xyzr", packed(xyzr)}, {"weights", packed(weights)}, {"indices", packed(indices)}};
}

// The skinned body: per welded vertex its stored position (what the joint matrices act on) and
// its joints and weights, at most 8, heaviest first and renormalised (`cut` counts the vertices
// that had more); a vertex no joint weighs has none and keeps its place.
void skinned_vertices(const Asset& rig, const WeldedBody& body, json& out, size_t& cut) {
  const auto file = rig.vertex_joints();
  const std::vector<Eigen::Vector3d> stored = rig.stored();
  const std::vector<size_t> first = first_file_vertices(body);
  size_t k = 1;
  for (const auto& f : file) k = std::max(k, std::min<size_t>(f.size(), 8));
  std::vector<Eigen::Vector3d> positions;
  std::vector<uint32_t> joints(k * first.size(), 0);
  std::vector<float> weights(k * first.size(), 0.0f);
  cut = 0;
  for (size_t v = 0; v < first.size(); ++v) {
    positions.push_back(stored[first[v]]);
    auto pairs = file[first[v]];
    std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    if (pairs.size() > k) ++cut, pairs.resize(k);
    double sum = 0;
    for (const auto& p : pairs) sum += p.second;
    for (size_t i = 0; i < pairs.size(); ++i) {
      joints[k * v + i] = uint32_t(pairs[i].first);
      weights[k * v + i] = float(pairs[i].second / sum);
    }
  }
  out["stored"] = packed(xyz_of(positions));
  out["influences"] = k;
  out["joints"] = packed(joints);
  out["weights"] = packed(weights);
}

// Joint matrices (column-major, float) of every asset joint, frame after frame.
void append_matrices(const std::vector<Eigen::Matrix4d>& m, std::vector<float>& out) {
  for (const Eigen::Matrix4d& j : m)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) out.push_back(float(j(r, c)));
}

json clip_data(const Asset& rig, size_t clip) {
  const AssetClip& c = rig.clips()[clip];
  size_t frames = 1;
  if (c.end > 0) frames = std::min(kPageMaxFrames, size_t(std::llround(c.end * kPageFramesPerSecond)) + 1);
  frames = std::max<size_t>(frames, c.end > 0 ? 2 : 1);
  std::vector<float> matrices;
  for (size_t f = 0; f < frames; ++f)
    append_matrices(rig.joint_matrices(clip, frames > 1 ? c.end * double(f) / double(frames - 1) : 0.0), matrices);
  return {{"name", c.name}, {"frames", frames}, {"seconds", c.end}, {"joints", rig.joints().size()},
          {"matrices", packed(matrices)}};
}

std::string html_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else out += c;
  }
  return out;
}

}  // namespace

json page_data(const ProxyModel& proxy, const std::string& name, const std::string& up) {
  std::vector<float> xyzr;
  std::vector<std::string> names;
  for (const ProxyPose& p : proxy.poses) {
    names.push_back(p.name);
    for (const Sphere& s : p.spheres) {
      for (int c = 0; c < 3; ++c) xyzr.push_back(float(s.center[c]));
      xyzr.push_back(float(s.radius));
    }
  }
  std::vector<uint32_t> sphere_site(proxy.sphere_sites.begin(), proxy.sphere_sites.end());
  json data = {{"name", name},
               {"up", up},
               {"spheres", {{"count", proxy.sphere_count()}, {"poses", names}, {"xyzr", packed(xyzr)}}},
               {"sites", {{"xyz", packed(xyz_of(proxy.sites))}, {"sphere_site", packed(sphere_site)}}},
               {"skin", nullptr},
               {"body", nullptr},
               {"clips", json::array()}};
  if (!proxy.skin.empty()) data["skin"] = skin_data(proxy.skin);
  return data;
}

void add_blended_body(json& data, const ProxyModel& proxy, const std::vector<TriMesh>& meshes) {
  json body = body_frame(meshes.at(0));
  json poses = json::array();
  for (const TriMesh& m : meshes) poses.push_back(packed(xyz_of(m.vertices)));
  body["poses"] = poses;
  body["vertex_site"] = packed(nearest_sites(meshes[0].vertices, proxy.sites));
  data["body"] = body;
}

void add_skinned_body(json& data, const ProxyModel& proxy, const Asset& rig, const WeldedBody& body) {
  json b = body_frame(body.rest);
  b["rest"] = packed(xyz_of(body.rest.vertices));
  size_t cut = 0;
  skinned_vertices(rig, body, b, cut);
  b["influences_cut"] = cut;
  data["body"] = b;
  const std::vector<size_t> asset_joint = rig.joints_named(proxy.skin.joints);
  data["skin"]["asset_joint"] = asset_joint;
  json clips = json::array();
  for (size_t c = 0; c < rig.clips().size(); ++c) clips.push_back(clip_data(rig, c));
  std::vector<float> rest;
  append_matrices(rig.rest_joint_matrices(), rest);
  clips.push_back({{"name", "bind pose"}, {"frames", 1}, {"seconds", 0.0}, {"joints", rig.joints().size()},
                   {"matrices", packed(rest)}});
  data["clips"] = clips;
}

std::string page_html(const json& data, const std::string& output) {
  if (kPageBundleSize == 0)
    fail_unsupported(output, "this build has no page script (web/node_modules was missing when it was built: run "
                             "scripts/setup.sh, then build again)");
  // In a <script> element nothing may read as "</script": '<' only occurs in JSON strings, where
  // \u003c stands for it.
  const std::string text = data.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) escaped += c == '<' ? std::string("\\u003c") : std::string(1, c);
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         html_escaped(data.value("name", std::string("proxy"))) + " \xc2\xb7 sphere proxy</title>\n</head>\n<body>\n" +
         "<script type=\"application/json\" id=\"spx-data\">" + escaped + "</script>\n<script>" +
         std::string(kPageBundle, kPageBundleSize) + "</script>\n</body>\n</html>\n";
}

}  // namespace spx
