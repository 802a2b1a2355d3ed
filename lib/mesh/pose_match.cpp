#include "mesh/pose_match.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <numeric>

#include <unordered_map>

#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

using Edge = std::pair<int, int>;
Edge edge_key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

// The triangles on each undirected edge.
std::map<Edge, std::vector<int>> edge_faces(const TriMesh& m) {
  std::map<Edge, std::vector<int>> out;
  for (size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) out[edge_key(m.triangles[t][k], m.triangles[t][(k + 1) % 3])].push_back(int(t));
  return out;
}

// Each vertex's class by how the mesh connects around it, the same in any numbering of vertices
// and faces: Weisfeiler-Lehman refinement of vertex degrees (each round hashes a vertex's class
// with the sorted classes of its neighbours).
std::vector<uint64_t> connectivity_classes(const TriMesh& m, int rounds) {
  std::vector<std::vector<int>> neighbours(m.vertices.size());
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) neighbours[size_t(t[k])].push_back(t[(k + 1) % 3]), neighbours[size_t(t[(k + 1) % 3])].push_back(t[k]);
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  std::vector<uint64_t> label(m.vertices.size()), next(label.size());
  for (size_t v = 0; v < label.size(); ++v) label[v] = neighbours[v].size();
  std::vector<uint64_t> around;
  for (int r = 0; r < rounds; ++r) {
    for (size_t v = 0; v < label.size(); ++v) {
      around.clear();
      for (int u : neighbours[v]) around.push_back(label[size_t(u)]);
      std::sort(around.begin(), around.end());
      uint64_t h = fnv1a(kFnvOffset, &label[v], sizeof(uint64_t));
      next[v] = fnv1a(h, around.data(), around.size() * sizeof(uint64_t));
    }
    label.swap(next);
  }
  return label;
}

class Matcher {
 public:
  Matcher(const TriMesh& rest, const TriMesh& pose)
      : rest_(rest), pose_(pose), rest_edges_(edge_faces(rest)), pose_edges_(edge_faces(pose)) {
    to_rest_.assign(pose.vertices.size(), -1);
    to_pose_.assign(rest.vertices.size(), -1);
    rest_face_of_.assign(pose.triangles.size(), -1);
    rest_face_used_.assign(rest.triangles.size(), 0);
  }

  // Maps every pose triangle, one edge-connected piece at a time, each grown from its first
  // unmapped triangle. A symmetric piece (a tube, a sphere) matches in several ways, and only
  // one puts each vertex where it belongs, so: the same vertex numbers if they match whole;
  // else, of the matches seeded at the rest triangle in the same place in the list or at the
  // nearest ones, the one that moves the vertices least; else any match at all.
  bool run() {
    anchor_pieces();
    for (size_t p = 0; p < pose_.triangles.size(); ++p) {
      if (rest_face_of_[p] >= 0) continue;
      if (!seed_piece(int(p))) return false;
    }
    return true;
  }
  const std::vector<int>& to_rest() const { return to_rest_; }

 private:
  static constexpr size_t kNearest = 8, kMaxSeeds = 64;
  static constexpr int kClassRounds = 6;

  // Pieces with a triangle whose corners are each the only vertex of their connectivity class,
  // in the pose and in the rest alike: that triangle's image is known whatever moved where,
  // so the piece grows from it. Symmetric pieces (tubes, spheres) have none and are left to
  // seed_piece.
  void anchor_pieces() {
    const std::vector<uint64_t> rest_class = connectivity_classes(rest_, kClassRounds);
    const std::vector<uint64_t> pose_class = connectivity_classes(pose_, kClassRounds);
    std::unordered_map<uint64_t, int> rest_unique, pose_count;
    for (size_t v = 0; v < rest_class.size(); ++v) {
      auto [it, fresh] = rest_unique.emplace(rest_class[v], int(v));
      if (!fresh) it->second = -1;
    }
    for (uint64_t c : pose_class) ++pose_count[c];
    std::map<std::array<int, 3>, int> rest_face;
    for (size_t r = 0; r < rest_.triangles.size(); ++r) rest_face.emplace(sorted(rest_.triangles[r]), int(r));
    for (size_t p = 0; p < pose_.triangles.size(); ++p) {
      if (rest_face_of_[p] >= 0) continue;
      std::array<int, 3> corners{};
      bool known = true;
      for (int k = 0; k < 3 && known; ++k) {
        const uint64_t c = pose_class[size_t(pose_.triangles[p][k])];
        const auto it = rest_unique.find(c);
        known = pose_count[c] == 1 && it != rest_unique.end() && it->second >= 0;
        if (known) corners[size_t(k)] = it->second;
      }
      if (!known) continue;
      const auto face = rest_face.find(sorted(Eigen::Vector3i(corners[0], corners[1], corners[2])));
      if (face != rest_face.end()) try_grow(int(p), face->second, corners);
    }
  }

  bool seed_piece(int p) {
    const Eigen::Vector3i& pt = pose_.triangles[size_t(p)];
    for (size_t r = 0; r < rest_.triangles.size(); ++r)
      if (!rest_face_used_[r] && sorted(rest_.triangles[r]) == sorted(pt) && try_grow(p, int(r), {pt[0], pt[1], pt[2]}))
        return true;

    std::vector<int> candidates;
    if (size_t(p) < rest_.triangles.size() && !rest_face_used_[size_t(p)]) candidates.push_back(p);
    std::vector<std::pair<double, int>> others;
    const Eigen::Vector3d c = centroid(pose_, p);
    for (size_t r = 0; r < rest_.triangles.size(); ++r)
      if (!rest_face_used_[r] && int(r) != p) others.emplace_back((centroid(rest_, int(r)) - c).squaredNorm(), int(r));
    const size_t keep = std::min(others.size(), kMaxSeeds);
    std::partial_sort(others.begin(), others.begin() + std::ptrdiff_t(keep), others.end());
    for (size_t i = 0; i < keep; ++i) candidates.push_back(others[i].second);

    // The least-moving match among the likely seeds.
    double best_cost = std::numeric_limits<double>::infinity();
    std::array<int, 3> best{};
    int best_face = -1;
    for (size_t i = 0; i < candidates.size() && i < kNearest + 1; ++i)
      for (int perm = 0; perm < 6; ++perm) {
        const std::array<int, 3> corners = permuted(candidates[i], perm);
        const Snapshot before = snapshot();
        if (grow(p, candidates[i], corners)) {
          double cost = 0;
          for (size_t k = before.bound; k < bound_.size(); ++k)
            cost += (pose_.vertices[size_t(bound_[k])] - rest_.vertices[size_t(to_rest_[size_t(bound_[k])])]).squaredNorm();
          if (cost < best_cost) best_cost = cost, best = corners, best_face = candidates[i];
        }
        restore(before);
      }
    if (best_face >= 0) return try_grow(p, best_face, best);
    // A pose that really differs fails every seed, each after a long walk: bound the search.
    for (size_t i = kNearest + 1; i < candidates.size(); ++i)
      for (int perm = 0; perm < 6; ++perm)
        if (try_grow(p, candidates[i], permuted(candidates[i], perm))) return true;
    return false;
  }

  std::array<int, 3> permuted(int r, int perm) const {
    static const int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    const Eigen::Vector3i& rt = rest_.triangles[size_t(r)];
    return {rt[kPerm[perm][0]], rt[kPerm[perm][1]], rt[kPerm[perm][2]]};
  }

  bool try_grow(int p, int r, const std::array<int, 3>& corners) {
    const Snapshot before = snapshot();
    if (grow(p, r, corners)) return true;
    restore(before);
    return false;
  }

  static Eigen::Vector3d centroid(const TriMesh& m, int t) {
    const Eigen::Vector3i& f = m.triangles[size_t(t)];
    return (m.vertices[size_t(f[0])] + m.vertices[size_t(f[1])] + m.vertices[size_t(f[2])]) / 3;
  }

  static std::array<int, 3> sorted(const Eigen::Vector3i& t) {
    std::array<int, 3> k{t[0], t[1], t[2]};
    std::sort(k.begin(), k.end());
    return k;
  }

  bool bind(int pv, int rv) {
    if (to_rest_[size_t(pv)] == rv && to_pose_[size_t(rv)] == pv) return true;
    if (to_rest_[size_t(pv)] >= 0 || to_pose_[size_t(rv)] >= 0) return false;
    to_rest_[size_t(pv)] = rv;
    to_pose_[size_t(rv)] = pv;
    bound_.push_back(pv);
    return true;
  }

  bool pair_faces(int p, int r, const std::array<int, 3>& corners) {
    if (rest_face_used_[size_t(r)]) return false;
    for (int k = 0; k < 3; ++k)
      if (!bind(pose_.triangles[size_t(p)][k], corners[size_t(k)])) return false;
    rest_face_of_[size_t(p)] = r;
    rest_face_used_[size_t(r)] = 1;
    paired_.push_back(p);
    return true;
  }

  // Pairs pose triangle p with rest triangle r (pose corner k to rest vertex corners[k]), then walks across
  // the pose's manifold edges: the triangle across an edge must meet the rest triangle across
  // the image of that edge, and its third corner the other's third corner.
  bool grow(int p, int r, const std::array<int, 3>& corners) {
    if (!pair_faces(p, r, corners)) return false;
    std::vector<int> queue{p};
    while (!queue.empty()) {
      const int f = queue.back();
      queue.pop_back();
      const Eigen::Vector3i& pt = pose_.triangles[size_t(f)];
      for (int k = 0; k < 3; ++k) {
        const int a = pt[k], b = pt[(k + 1) % 3];
        const auto across = pose_edges_.find(edge_key(a, b));
        if (across == pose_edges_.end() || across->second.size() != 2) continue;
        const int q = across->second[0] == f ? across->second[1] : across->second[0];
        if (rest_face_of_[size_t(q)] >= 0) continue;
        const auto image = rest_edges_.find(edge_key(to_rest_[size_t(a)], to_rest_[size_t(b)]));
        if (image == rest_edges_.end() || image->second.size() != 2) return false;
        const int s = image->second[0] == rest_face_of_[size_t(f)] ? image->second[1] : image->second[0];
        // q's corners: a and b map to their images, the third to s's third corner.
        const Eigen::Vector3i& qt = pose_.triangles[size_t(q)];
        const Eigen::Vector3i& st = rest_.triangles[size_t(s)];
        int third = -1;
        for (int j = 0; j < 3; ++j)
          if (st[j] != to_rest_[size_t(a)] && st[j] != to_rest_[size_t(b)]) third = st[j];
        if (third < 0) return false;
        std::array<int, 3> corners{};
        for (int j = 0; j < 3; ++j)
          corners[size_t(j)] = qt[j] == a ? to_rest_[size_t(a)] : qt[j] == b ? to_rest_[size_t(b)] : third;
        if (!pair_faces(q, s, corners)) return false;
        queue.push_back(q);
      }
    }
    return true;
  }

  struct Snapshot { size_t bound, paired; };
  Snapshot snapshot() const { return {bound_.size(), paired_.size()}; }
  void restore(const Snapshot& s) {
    for (size_t i = s.bound; i < bound_.size(); ++i) {
      to_pose_[size_t(to_rest_[size_t(bound_[i])])] = -1;
      to_rest_[size_t(bound_[i])] = -1;
    }
    bound_.resize(s.bound);
    for (size_t i = s.paired; i < paired_.size(); ++i) {
      rest_face_used_[size_t(rest_face_of_[size_t(paired_[i])])] = 0;
      rest_face_of_[size_t(paired_[i])] = -1;
    }
    paired_.resize(s.paired);
  }

  const TriMesh &rest_, &pose_;
  std::map<Edge, std::vector<int>> rest_edges_, pose_edges_;
  std::vector<int> to_rest_, to_pose_, rest_face_of_, bound_, paired_;
  std::vector<char> rest_face_used_;
};

}  // namespace

std::vector<int> match_pose_vertices(const TriMesh& rest, const TriMesh& pose, const std::string& path) {
  if (pose.vertices.size() != rest.vertices.size() || pose.triangles.size() != rest.triangles.size())
    fail_input(path, "has " + std::to_string(pose.vertices.size()) + " distinct vertices and " +
                         std::to_string(pose.triangles.size()) + " triangles, the rest mesh " +
                         std::to_string(rest.vertices.size()) + " and " + std::to_string(rest.triangles.size()));
  Matcher m(rest, pose);
  if (!m.run()) {
    // Say how they differ: vertices with another number of neighbours, if any.
    auto degrees = [](const TriMesh& mesh) {
      std::vector<int> count(mesh.vertices.size(), 0);
      for (const auto& [edge, faces] : edge_faces(mesh)) ++count[size_t(edge.first)], ++count[size_t(edge.second)];
      std::sort(count.begin(), count.end());
      return count;
    };
    const std::vector<int> a = degrees(rest), b = degrees(pose);
    size_t differ = 0;
    for (size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
    fail_input(path, differ > 0 ? "its triangles connect its vertices otherwise than the rest mesh's: " +
                                      std::to_string(differ) + " vertices have another number of neighbours"
                                : "its triangles connect its vertices otherwise than the rest mesh's: no order of "
                                  "vertices and faces makes them the same triangles");
  }
  std::vector<int> map = m.to_rest();
  if (std::count(map.begin(), map.end(), -1) > 0)
    fail_input(path, "has vertices that no triangle uses, which cannot be matched to the rest mesh's");
  return map;
}

}  // namespace spx
