#pragma once
// Sphere unions as triangles to look at (Blender, any glTF/PLY viewer).
#include <string>

#include "mesh/mesh.hpp"
#include "mesh/union_distance.hpp"
#include "io/proxy_file.hpp"

namespace spx {

// One named mesh of a scene, optionally with a colour per vertex.
struct SceneNode {
  std::string name;
  TriMesh mesh;
  std::vector<Eigen::Vector3f> colors;  // empty, or one per vertex (0..1)
};

// Binary glTF (".glb", one node per entry) or binary PLY (".ply", the entries merged) via assimp.
std::string encode_scene(const std::vector<SceneNode>& nodes, const std::string& extension);

// The paper's error pictures: white where the union meets the surface, through yellow to red
// at `scale` and beyond; blue where the union pokes out (negative distance).
std::vector<Eigen::Vector3f> error_colors(const std::vector<double>& signed_error, double scale);

// Binary glTF with one node per pose (named after it), laid side by side along +x when
// `spread` is set; or binary PLY of one pose. The format comes from the extension.
// The error-coloured meshes (and their sphere unions) of `poses`: every pose for .glb, laid
// `step` apart along x; pose number `pose` alone for .ply.
std::string encode_error_scene(const std::vector<PoseError>& poses, const std::string& extension, int pose,
                               double scale, double step);
// Pose number `pose` among `count` poses, or spx::Error (exit 1, the option "pose"): "no pose 9
// (there are poses 0..2)". What encode_error_scene asks of its .ply pose, askable before the work.
void check_pose_number(int pose, size_t count);

std::string encode_preview(const ProxyModel& proxy, const std::string& extension, int pose, bool spread);

}  // namespace spx
