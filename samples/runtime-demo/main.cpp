// Minimal host: load a .spx, blend with the global weights given (or with a morph-target body's
// weights, or skin a rigged body's spheres with the joint matrices given), print the spheres.
//   runtime-demo FILE.spx [w0 w1 ...]      (no weights: the rest pose)
//   runtime-demo FILE.spx --morph w1 w2 ... (one weight per example after the rest)
//   runtime-demo FILE.spx --skin m0 m1 ... (joint_count column-major 4x4 matrices)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "spx_runtime.h"

int main(int argc, char** argv) {
  const char* usage =
      "usage: runtime-demo FILE.spx [w0 w1 ...]  (no weights: the rest pose)\n"
      "       runtime-demo FILE.spx --morph w1 w2 ...  (morph-target weights, one per example after the rest)\n"
      "       runtime-demo FILE.spx --skin m0 m1 ...  (16 numbers per joint, column-major)\n";
  if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf("%s", usage);
    return 0;
  }
  if (argc < 2) {
    std::fprintf(stderr, "%s", usage);
    return 1;
  }
  spx::Proxy proxy;
  spx::Status status = spx::load_file(argv[1], &proxy);
  if (status != spx::SPX_OK) {
    std::fprintf(stderr, "Error: %s: %s (status %d)\n", argv[1], spx::status_string(status), int(status));
    return 2;
  }
  if (argc >= 3 && std::strcmp(argv[2], "--skin") == 0) {
    std::vector<float> matrices;
    for (int i = 3; i < argc; ++i) matrices.push_back(std::strtof(argv[i], nullptr));
    std::vector<float> xyzr(size_t(proxy.sphere_count()) * 4);
    status = spx::skin(proxy, matrices.data(), int(matrices.size() / 16), xyzr.data());
    if (status != spx::SPX_OK || matrices.size() % 16 != 0) {
      std::fprintf(stderr, "Error: skin: %s (status %d; this file has %u joints)\n",
                   matrices.size() % 16 ? "give 16 numbers per joint" : spx::status_string(status), int(status),
                   proxy.joint_count());
      return 1;
    }
    std::printf("# %u spheres, %u joints\n# x y z r\n", proxy.sphere_count(), proxy.joint_count());
    for (uint32_t j = 0; j < proxy.sphere_count(); ++j)
      std::printf("%.9g %.9g %.9g %.9g\n", xyzr[4 * j], xyzr[4 * j + 1], xyzr[4 * j + 2], xyzr[4 * j + 3]);
    return 0;
  }
  const bool morph = argc >= 3 && std::strcmp(argv[2], "--morph") == 0;
  std::vector<float> weights(proxy.pose_count(), 0.0f);
  if (morph) {
    weights.clear();
    for (int i = 3; i < argc; ++i) weights.push_back(std::strtof(argv[i], nullptr));
  } else if (argc == 2) {
    weights[0] = 1;
  } else {
    weights.assign(size_t(argc - 2), 0.0f);
    for (int i = 2; i < argc; ++i) weights[size_t(i - 2)] = std::strtof(argv[i], nullptr);
  }
  std::vector<float> centers(size_t(proxy.sphere_count()) * 3), radii(proxy.sphere_count());
  status = morph ? spx::blend_morph(proxy, weights.data(), uint32_t(weights.size()), centers.data(), radii.data())
                 : spx::blend_global(proxy, weights.data(), uint32_t(weights.size()), centers.data(), radii.data());
  if (status != spx::SPX_OK) {
    std::fprintf(stderr, "Error: blend: %s (status %d; this file has %u poses%s)\n", spx::status_string(status),
                 int(status), proxy.pose_count(), morph ? ", the rest's weight not given" : "");
    return 1;
  }
  std::printf("# %u spheres, %u poses:", proxy.sphere_count(), proxy.pose_count());
  for (uint32_t i = 0; i < proxy.pose_count(); ++i) std::printf(" %s", proxy.pose_name(i));
  std::printf("\n# x y z r\n");
  for (uint32_t j = 0; j < proxy.sphere_count(); ++j)
    std::printf("%.9g %.9g %.9g %.9g\n", centers[3 * j], centers[3 * j + 1], centers[3 * j + 2], radii[j]);  // exact for floats
  return 0;
}
