#include "metrics/motion_eval.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "io/spx_writer.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/union_distance.hpp"
#include "metrics/proxy_eval.hpp"
#include "metrics/simplex_fit.hpp"
#include "runtime/spx_runtime.h"

namespace spx {

const char* motion_runtime_name(int runtime) {
  static const char* names[kMotionRuntimes] = {"skinned", "rigid_per_bone", "best_fit_blend", "morph_blend",
                                               "global_blend"};
  return names[runtime];
}

bool MotionResult::measured(int runtime) const {
  return std::find(runtimes.begin(), runtimes.end(), runtime) != runtimes.end();
}

namespace {

SphereSet from_xyzr(const std::vector<float>& xyzr) {
  SphereSet s(xyzr.size() / 4);
  for (size_t i = 0; i < s.size(); ++i)
    s[i] = {Eigen::Vector3d(xyzr[4 * i], xyzr[4 * i + 1], xyzr[4 * i + 2]), double(xyzr[4 * i + 3])};
  return s;
}

// The frames' triangles, where the first frame's close the body: one hierarchy refitted to each
// frame on them, instead of a MeshQuery's trees and winding number built for every frame (most
// of a clip's measuring).
struct ClipTopology {
  explicit ClipTopology(const TriMesh& first)
      : triangles(first.triangles),
        hierarchy(first),
        one_piece(BoundaryParts(first, WindingNumber::on_first_use(first)).whole()) {}
  const std::vector<Eigen::Vector3i>& triangles;  // the first frame's, which outlives this
  DeformingQuery hierarchy;
  // Where solid_boundary probes nothing (a single closed surface, by its topology alone, the
  // same in every frame) the solid's surface is the whole mesh. No winding number is built.
  bool one_piece;
};

// A frame's body as the measures ask it: the solid's surface vertices, and signed distances to
// that surface (negative inside: winding number > 1/2).
class FrameBody {
 public:
  FrameBody(const TriMesh& mesh, const ClipTopology& clip) {
    const bool on_clip = clip.hierarchy.closed() && mesh.triangles == clip.triangles;
    if (on_clip) shape_.emplace(clip.hierarchy.shape(mesh.vertices));
    if (on_clip && clip.one_piece) {
      vertices_ = &mesh.vertices;
      return;
    }
    // Several pieces: the boundary leaves out what lies inside another piece.
    query_ = std::make_unique<MeshQuery>(mesh);
    if (shape_) query_->tell_inside_by(&*shape_);  // its ray count: the winding number off the surface
    vertices_ = &query_->surface().vertices;
  }
  const std::vector<Eigen::Vector3d>& surface_vertices() const { return *vertices_; }
  double signed_distance(const Eigen::Vector3d& p) const {
    if (query_) return query_->signed_distance(p);
    const double d = std::abs(shape_->signed_distance(p));
    return shape_->inside(p) ? -d : d;
  }

 private:
  std::optional<DeformingQuery::Shape> shape_;
  std::unique_ptr<MeshQuery> query_;
  const std::vector<Eigen::Vector3d>* vertices_ = nullptr;
};

// `spheres` against the frame's body.
FrameError measure_frame(const FrameBody& body, const SphereSet& spheres) {
  FrameError e;
  const std::vector<double> d = union_signed_distance(body.surface_vertices(), spheres);
  const ErrorStats stats = summarize_abs(d);
  e.median = stats.median;
  e.max = stats.max;
  for (const Sphere& s : spheres) {
    if (!(s.radius > 0)) {
      ++e.zero;
      continue;
    }
    const double signed_distance = body.signed_distance(s.center);
    e.overshoot = std::max(e.overshoot, s.radius + signed_distance);
    e.outside += signed_distance > 0;
  }
  return e;
}

// The column-major floats a host hands spx::skin.
std::vector<float> host_matrices(const std::vector<Eigen::Matrix4d>& joints) {
  std::vector<float> m(16 * joints.size());
  for (size_t j = 0; j < joints.size(); ++j) Eigen::Map<Eigen::Matrix4f>(m.data() + 16 * j) = joints[j].cast<float>();
  return m;
}

// Each sphere fixed to its heaviest joint: its rest centre moved by that joint's matrix alone.
std::vector<float> rigid_per_bone(const Proxy& runtime, const std::vector<float>& matrices) {
  std::vector<float> out(4 * size_t(runtime.sphere_count()));
  for (uint32_t i = 0; i < runtime.sphere_count(); ++i) {
    const float* s = runtime.skin_spheres() + 8 * size_t(i);
    const uint32_t* j = runtime.skin_joints() + 4 * size_t(i);
    const int heaviest = int(std::max_element(s + 4, s + 8) - (s + 4));
    const Eigen::Map<const Eigen::Matrix4f> m(matrices.data() + 16 * size_t(j[heaviest]));
    const Eigen::Vector4f c = m * Eigen::Vector4f(s[0], s[1], s[2], 1);
    for (int k = 0; k < 3; ++k) out[4 * i + k] = c[k];
    out[4 * i + 3] = s[3];
  }
  return out;
}

// The examples' vertices as the columns of A, kept in Gram form: G = A'A, and b = A'v per frame.
struct ExampleFit {
  Eigen::MatrixXd A, G;
  explicit ExampleFit(const std::vector<TriMesh>& examples) {
    if (examples.empty()) return;
    const size_t n = examples[0].vertices.size();
    A.resize(Eigen::Index(3 * n), Eigen::Index(examples.size()));
    for (size_t e = 0; e < examples.size(); ++e)
      for (size_t v = 0; v < n; ++v) A.block<3, 1>(Eigen::Index(3 * v), Eigen::Index(e)) = examples[e].vertices[v];
    G = A.transpose() * A;
  }
  Eigen::VectorXd weights(const TriMesh& frame) const {
    Eigen::VectorXd v(A.rows());
    for (size_t i = 0; i < frame.vertices.size(); ++i) v.segment<3>(Eigen::Index(3 * i)) = frame.vertices[i];
    return simplex_least_squares(G, A.transpose() * v);
  }
};

// A morph-target body's frame as a host without blend_morph would blend it: the global blend at
// the morph weights, the rest at 1 less their sum (as blend_morph makes them full; then clamped
// and normalised by the global blend's policy).
std::vector<float> global_weights(const std::vector<float>& morph) {
  std::vector<float> w(morph.size() + 1);
  detail::morph_to_full(morph.data(), uint32_t(w.size()), w.data());
  return w;
}

MotionRow measure_motion_frame(const Proxy& runtime, const MotionFrame& frame, const ExampleFit* fit,
                               const ClipTopology& clip, const std::string& source) {
  MotionRow row;
  row.time = frame.time, row.seen = frame.seen, row.between = frame.between;
  const FrameBody body(frame.mesh, clip);
  std::vector<float> xyzr(4 * size_t(runtime.sphere_count()));
  // The runtime's spheres, or exit 2 naming the frame: a host's float arithmetic overflows on
  // joint matrices or weights this large, and nothing could be measured there.
  auto must = [&](Status status, const char* what) {
    if (status != SPX_OK) fail_input("", std::string("the runtime cannot ") + what + ": " + status_string(status));
    if (!std::all_of(xyzr.begin(), xyzr.end(), [](float v) { return std::isfinite(v); }))
      fail_input(source, "at " + std::to_string(frame.time) + " s the runtime's spheres are not finite (" + what +
                             " in float, as a host does, overflows): the asset's motion is past a host's numbers");
  };
  if (runtime.has_skin()) {
    const std::vector<float> matrices = host_matrices(frame.joints);
    must(skin(runtime, matrices.data(), int(frame.joints.size()), xyzr.data()), "skin the proxy");
    row.error[kSkinned] = measure_frame(body, from_xyzr(xyzr));
    xyzr = rigid_per_bone(runtime, matrices);
    must(SPX_OK, "fix each sphere to its heaviest joint");
    row.error[kRigid] = measure_frame(body, from_xyzr(xyzr));
  } else {
    const std::vector<float>& w = frame.morph_weights;
    must(blend_morph_xyzr(runtime, w.data(), uint32_t(w.size()), xyzr.data()), "blend the proxy by morph weights");
    row.error[kMorph] = measure_frame(body, from_xyzr(xyzr));
    const std::vector<float> global = global_weights(w);
    must(blend_global_xyzr(runtime, global.data(), uint32_t(global.size()), xyzr.data()), "blend the proxy globally");
    row.error[kGlobal] = measure_frame(body, from_xyzr(xyzr));
  }
  if (fit) {
    const Eigen::VectorXd w = fit->weights(frame.mesh);
    row.blend_weights.assign(w.data(), w.data() + w.size());
    for (float& x : row.blend_weights) x = std::max(x, 0.0f);
    must(blend_global_xyzr(runtime, row.blend_weights.data(), uint32_t(w.size()), xyzr.data()),
         "blend the proxy at the best-fit weights");
    row.error[kBestBlend] = measure_frame(body, from_xyzr(xyzr));
  }
  return row;
}

// The frame's joints or weights fit the proxy, or exit 3 naming the time.
void check_frame_fits(const Proxy& runtime, const MotionFrame& f) {
  const std::string at = "frame at " + std::to_string(f.time) + " s has ";
  if (runtime.has_skin() && f.joints.size() != runtime.joint_count())
    fail_input("", at + std::to_string(f.joints.size()) + " joint matrices; the proxy's skin has " +
                       std::to_string(runtime.joint_count()));
  if (!runtime.has_skin() && f.morph_weights.size() + 1 != runtime.pose_count())
    fail_input("", at + std::to_string(f.morph_weights.size()) + " morph weights; the proxy has " +
                       std::to_string(runtime.pose_count() - 1) + " examples after the rest");
}

}  // namespace

MotionResult evaluate_motion(const ProxyModel& proxy, size_t frame_count, const std::function<MotionFrame(size_t)>& frame,
                             const std::vector<TriMesh>& examples, Log& log, const std::string& source) {
  if (!examples.empty() && examples.size() != proxy.poses.size())
    fail_option("poses", "the proxy has " + std::to_string(proxy.poses.size()) + " poses, " +
                             std::to_string(examples.size()) + " example meshes were given");
  const std::string bytes = encode_spx(proxy);
  Proxy runtime;
  const Status status = load_memory(bytes.data(), bytes.size(), &runtime);
  if (status != SPX_OK) fail_input("", std::string("runtime cannot load the proxy: ") + status_string(status));
  const ExampleFit fit(examples);
  MotionResult result;
  result.runtimes = runtime.has_skin() ? std::vector<int>{kSkinned, kRigid} : std::vector<int>{kMorph, kGlobal};
  if (!examples.empty()) result.runtimes.push_back(kBestBlend);
  result.rows.resize(frame_count);
  if (frame_count == 0) return result;
  const MotionFrame first_frame = frame(0);
  const ClipTopology clip(first_frame.mesh);
  auto measure = [&](const MotionFrame& f) {
    check_frame_fits(runtime, f);
    return measure_motion_frame(runtime, f, examples.empty() ? nullptr : &fit, clip, source);
  };
  // In batches, so progress is reported from one thread; every row lands in its own slot.
  const size_t batch = 16;
  for (size_t first = 0; first < frame_count; first += batch) {
    log.progress("measuring frames", first, frame_count);
    tbb::parallel_for(first, std::min(frame_count, first + batch),
                      [&](size_t i) { result.rows[i] = i == 0 ? measure(first_frame) : measure(frame(i)); });
  }
  std::vector<float> xyzr(4 * size_t(runtime.sphere_count()));
  if (runtime.has_skin()) {
    const std::vector<float> m = host_matrices(first_frame.joints);
    result.host_us = median_call_us([&] { skin(runtime, m.data(), int(m.size() / 16), xyzr.data()); });
  } else {
    const std::vector<float>& w = first_frame.morph_weights;
    result.host_us = median_call_us([&] { blend_morph_xyzr(runtime, w.data(), uint32_t(w.size()), xyzr.data()); });
  }
  return result;
}

}  // namespace spx
