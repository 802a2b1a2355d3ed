#pragma once
// A glTF asset made ready for assimp (5.2), which reads some valid ones wrong without a word: it
// copies the bytes of an integer accessor into floats where glTF allows integers for
// floating-point data (a skin weight of 255, normalized: 1, reads as 3.6e-43 and the poses come
// out wrong), fails on a Draco-compressed mesh with 32-bit indices, places a mesh instanced by a
// node once, skins every node's copy of a mesh one node skins, reads no node's morph weights,
// turns over a mirrored node that a clip moves, reads STEP keys and cubic splines as linear
// ones, fails on a channel of KHR_animation_pointer, and ignores the extensions an asset
// requires. Each function below mends one of those in the document and its binary buffer, which
// assimp then reads from memory (mesh/assimp_scene); the clips' mends are in
// mesh/gltf_clips.cpp, Draco's in mesh/gltf_draco.cpp.
#include <string>
#include <vector>

#include "core/gltf_file.hpp"

namespace spx {

// Exit 3 naming the first extension in `extensionsRequired` that the tools cannot honour. Those
// they can: KHR_draco_mesh_compression (draco_primitives_decoded), KHR_mesh_quantization
// (float_accessors), EXT_mesh_gpu_instancing (instances_as_nodes), KHR_animation_pointer
// (channels_as_assimp_reads), and those of materials, textures and lights, which change no
// geometry. (EXT_meshopt_compression is decoded as the file
// is read, core/gltf_meshopt, and is no longer listed by then.)
void check_required_extensions(const json& doc, const std::string& path);

// assimp 5.2 reads the indices of a KHR_draco_mesh_compression primitive as no data where they
// are 32-bit ("Invalid accessor without data", assimp issue 4789), so a Draco-compressed body
// with them (any over 65 535 vertices) failed to load. Each such primitive's stream is decoded
// here, by the Draco library assimp itself uses, into plain accessors: every attribute the
// extension names (its values converted to its accessor's component type and count, as the
// extension says the accessor describes the decoded data) and the triangles into the indices
// accessor (one made where the primitive has none); an accessor another primitive decoded before
// is copied, not overwritten. The extension leaves each primitive, and the file's lists once none
// carries it. Returns how many primitives changed. Exit 2 naming `path` where the stream does not
// decode or the extension names what the file does not have.
size_t draco_primitives_decoded(GltfFile& file, const std::string& path);

// assimp places a mesh that a node instances by EXT_mesh_gpu_instancing once, at the node, where
// renderers draw it at every instance (a car's wheels or bolts, as gltfpack -mi writes them). Each
// such node's instances become child nodes of its own, each the mesh at the instance's
// translation, rotation and scale (in the node's frame, as the extension says), and the node keeps
// its children but not the mesh. Returns how many nodes changed. Exit 2 naming `path` where the
// extension's attributes are not as it says.
size_t instances_as_nodes(GltfFile& file, const std::string& path);

// glTF skins a node, not a mesh, and a node's morph weights (`weights`) stand for its mesh's
// default ones. One mesh placed by a skinned node and by a node without that skin is drawn by
// each in its own way (the other node places it rigidly, or by a skin of its own). assimp gives
// the mesh itself the bones, so every node drew it where the skin does, and a rigid copy beside
// a character read as the character's triangles twice; and it reads no node's weights. Each way
// of drawing a mesh (a skin or none, and the node's weights or none) after the first gets a copy
// of it (the same primitives and accessors) to place, and a node's weights become its mesh's
// (which assimp gives each target, `aiAnimMesh::mWeight`). Returns how many meshes were added
// or given weights (0: the file is as it was).
size_t meshes_split_by_node(GltfFile& file);

// Rewrites as floats every integer accessor a reader takes as floating-point data: a mesh's
// attributes but its joints (JOINTS_n) and application-specific ones ("_NAME"), its morph
// targets' attributes, and clips' outputs (normalized rotations and morph weights). The values are
// the spec's: c / 255, c / 65535, max(c / 127, -1), max(c / 32767, -1) where normalized, else c;
// min and max too; a sparse accessor becomes dense. The new data goes at the end of the binary
// buffer. Returns how many accessors changed (0: the file is as it was). Exit 2 naming `path`
// where an accessor or its view is out of range.
size_t float_accessors(GltfFile& file, const std::string& path);

// assimp fills the paths a clip leaves a node without from the node's matrix decomposed, whose
// rotation takes a mirroring scale's sign (scale -1, 1, 1 becomes a half turn about x and scale
// -1, -1, -1), beside the scale the node itself gives: a mirrored part a clip moves turns over.
// Each mirrored node a clip moves (its scale's product below 0) gets the paths the clip leaves out
// as one-key channels holding its own translation, rotation or scale. Returns how many channels
// were added (0: the file is as it was).
size_t complete_mirrored_channels(GltfFile& file, const std::string& path);

// assimp reads every clip's keys as linear ones, so a STEP sampler's value glided between its keys
// where glTF holds it. Each STEP sampler is rewritten as a linear one holding each value until the
// next key, where it steps: that key is given twice, first with the value before (the key times
// stay the same, so do a clip's frames). Returns how many samplers changed.
size_t step_samplers_as_held_keys(GltfFile& file, const std::string& path);

// The key times of a clip whose cubic splines were made linear (cubic_samplers_as_keys): the keys
// added between the asset's are no frames of its.
struct AddedKeys {
  std::vector<double> asset_times;  // every key time of the clip's samplers in the file (s), sorted
  size_t added = 0;                 // keys added, over the clip's samplers
};

// assimp reads a CUBICSPLINE sampler's values at its keys and glides linearly between them, where
// glTF follows the Hermite spline of its tangents (a rotation's then normalized). Each is rewritten
// as a linear sampler with keys between its own as often as the tools sample a clip
// (clip_steps_between, so half-way is one), valued on the spline: exact at every time the tools
// ask of a clip, linear only between those. `added[a]` receives clip a's key times (empty where
// none of its samplers changed). Returns how many samplers changed.
size_t cubic_samplers_as_keys(GltfFile& file, const std::string& path, std::vector<AddedKeys>& added);

// assimp 5.2 reads a channel's path it does not know as a translation, so a clip with a
// KHR_animation_pointer channel (path "pointer": a material's colour, a light's intensity)
// failed the whole file ("GLTF: elemSize 16 > targetElemSize 12"), and it drops a channel with no
// node without a word. A pointer to a node's translation, rotation, scale or morph weights
// ("/nodes/3/rotation") becomes the plain channel it stands for, and one to a mesh's morph weights
// ("/meshes/1/weights") a channel of each node placing that mesh without weights of its own; every
// other channel moves no geometry and leaves its clip, `passed_over[a]` naming clip a's ("animations[0].channels[4]
// (KHR_animation_pointer '/materials/0/emissiveFactor')"). Returns how many channels changed.
size_t channels_as_assimp_reads(GltfFile& file, std::vector<std::vector<std::string>>& passed_over);

// What the clips' mends tell whoever reads the clips, per clip in the file's order.
struct ClipMends {
  std::vector<AddedKeys> added_keys;                  // cubic_samplers_as_keys
  std::vector<std::vector<std::string>> passed_over;  // channels_as_assimp_reads
};

}  // namespace spx
