#pragma once
// sphere-pack's cache (`--cache DIR`): the candidates no tolerance or budget changes, kept between
// runs, so that a run with another tolerance or budget on the same field skips them and writes the
// same spheres to the byte. DIR/candidates-KEY.bin holds the field's voxel candidates and the
// tangent balls of the samples asked so far (a spaced cover asks some of them, a later run more).
// KEY hashes what they are made of: the field, the mesh, the samples, the radius limits, the
// project's version and the program's build (a tool rebuilt from other code makes them afresh).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/sphere.hpp"
#include "io/dense_field.hpp"
#include "pack/candidates.hpp"

namespace spx {

class CandidateCache {
 public:
  CandidateCache() = default;  // no cache: every step computed
  // The cache for this field, mesh, samples and limits in `dir` (made if it is not there: a
  // folder that cannot be made fails, cannot_write). Reads its file where it is this key's; a
  // file cut short or another key's is taken as empty, and written over.
  CandidateCache(const std::string& dir, const DenseField& field, const TriMesh& mesh, const SurfaceSamples& samples,
                 const CandidateOptions& limits);

  // The voxel candidates: the cache's, or `make`'s (then kept).
  SphereSet voxel_candidates(const std::function<SphereSet()>& make);
  // The balls of the samples `which`: the cache's, and `make`'s for the samples it lacks (given
  // in the order of `which`; then kept).
  std::vector<SampleBalls> tangent_balls(const std::vector<uint32_t>& which,
                                         const std::function<std::vector<SampleBalls>(const std::vector<uint32_t>&)>& make);
  // Writes the file (atomically) where this run added to it. A file that cannot be written is no
  // reason to fail: returns its error's message, else empty.
  std::string save() const;

  bool active() const { return !path_.empty(); }
  const std::string& file() const { return path_; }
  size_t balls_read() const { return balls_read_; }
  size_t balls_made() const { return balls_made_; }
  bool voxels_read() const { return voxels_read_; }

 private:
  std::string path_, key_;
  std::optional<SphereSet> voxels_;
  std::vector<char> known_;  // per sample: its balls are in balls_
  std::vector<SampleBalls> balls_;
  size_t balls_read_ = 0, balls_made_ = 0;
  bool voxels_read_ = false, changed_ = false;
};

}  // namespace spx
