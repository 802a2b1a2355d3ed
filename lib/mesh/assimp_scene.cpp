#include "mesh/assimp_scene.hpp"

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/gltf_file.hpp"

namespace spx {

const aiScene* read_scene(Assimp::Importer& importer, const std::string& path, unsigned flags, const std::string& what) {
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene && scene->mRootNode) return scene;
  const std::string error = importer.GetErrorString();
  const std::string ext = lower_extension(path);
  if (ext == ".gltf" || ext == ".glb") {
    const GltfFile file = read_gltf_file(path);  // throws saying what is wrong with the container
    if (file.doc.value("meshes", json::array()).empty()) fail_input(path, "contains no mesh");
    if (ext == ".gltf") {
      const std::string glb = encode_glb(file);
      scene = importer.ReadFileFromMemory(glb.data(), glb.size(), flags, "glb");
      if (scene && scene->mRootNode) return scene;
    }
  }
  fail_input(path, "cannot read " + what + ": " + error);
}

}  // namespace spx
