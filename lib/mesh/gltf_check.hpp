#pragma once
// A glTF's skins, node tree and clips checked against the rules of the glTF 2.0 spec that assimp
// 5.2 follows without checking. Broken, it crashes (a skin without joints) or reads another body
// without a word: a node with two parents moved by both, a skin's matrices read past their
// accessor, a vertex weighted to a joint the skin lacks, a skin index past the list dropped (the
// body then rigid), a sampler's missing values or its times out of order read as other keys.
#include <string>

#include "core/gltf_file.hpp"

namespace spx {

// Exit 2 naming `path` and the member (`skins[0].joints[3]`) at the first rule broken: every
// index in range (a node's children, mesh and skin; a skin's joints, skeleton and matrices; a
// clip's samplers and their accessors); every node one parent at most, and none its own
// ancestor; a skin's joints given, none twice, with at least as many MAT4 float matrices as
// joints; every joint a weighted vertex names within its skin; a sampler's key times SCALAR
// floats, finite and never going back, with a value of the channel's type for each (three for a
// cubic spline; one per morph target for weights).
void check_gltf_rules(const GltfFile& file, const std::string& path);

// A skin without inverseBindMatrices, which the spec reads as identity matrices, crashes assimp
// 5.2: each such skin is given an accessor of identity matrices, one per joint. Returns how many
// skins changed.
size_t skins_given_bind_matrices(GltfFile& file);

}  // namespace spx
