/* The C API from C (C99): loads a .spx and prints the blend at the weights given, in
 * runtime-demo's format, three ways (split layout, xyzr, and the local blend with those weights
 * at every site, normalised once). tests/cli/bindings.sh compares every line with runtime-demo,
 * which calls the C++ header directly.
 *   c_api_check FILE.spx W0 W1 ...
 *   c_api_check FILE.spx --morph W1 W2 ...   (split layout and xyzr, as runtime-demo --morph prints it)
 *   c_api_check FILE.spx --skin M...   (the skin, as runtime-demo --skin prints it) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spx_c.h"

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  spx_proxy* proxy = NULL;
  int s = spx_load_file(argv[1], &proxy);
  if (s != SPX_C_OK) {
    fprintf(stderr, "Error: %s: %s\n", argv[1], spx_status_string(s));
    return 1;
  }
  const uint32_t n = spx_sphere_count(proxy), p = spx_pose_count(proxy), sites = spx_site_count(proxy);
  if (strcmp(argv[2], "--skin") == 0) {
    const int values = argc - 3;
    float* m = malloc(sizeof(float) * (size_t)(values > 0 ? values : 1));
    float* out = malloc(sizeof(float) * 4 * n);
    for (int i = 0; i < values; ++i) m[i] = strtof(argv[i + 3], NULL);
    s = spx_skin(proxy, m, values / 16, out);
    if (s == SPX_C_OK) {
      printf("# %u spheres, %u joints\n# x y z r\n", n, spx_joint_count(proxy));
      for (uint32_t j = 0; j < n; ++j) printf("%.9g %.9g %.9g %.9g\n", out[4 * j], out[4 * j + 1], out[4 * j + 2], out[4 * j + 3]);
    } else {
      fprintf(stderr, "Error: skin: %s\n", spx_status_string(s));
    }
    free(m), free(out);
    spx_free(proxy);
    return s != SPX_C_OK;
  }
  if (strcmp(argv[2], "--morph") == 0) {
    const uint32_t count = (uint32_t)(argc - 3);
    float* w = malloc(sizeof(float) * (count > 0 ? count : 1));
    float* c = malloc(sizeof(float) * 3 * n);
    float* r = malloc(sizeof(float) * n);
    float* xyzr = malloc(sizeof(float) * 4 * n);
    for (uint32_t i = 0; i < count; ++i) w[i] = strtof(argv[i + 3], NULL);
    s = spx_blend_morph(proxy, w, count, c, r);
    if (s == SPX_C_OK) s = spx_blend_morph_xyzr(proxy, w, count, xyzr);
    if (s == SPX_C_OK) {
      printf("# %u spheres, %u poses:", n, p);
      for (uint32_t i = 0; i < p; ++i) printf(" %s", spx_pose_name(proxy, i));
      printf("\n# x y z r\n");
      for (uint32_t j = 0; j < n; ++j) printf("%.9g %.9g %.9g %.9g\n", c[3 * j], c[3 * j + 1], c[3 * j + 2], r[j]);
      for (uint32_t j = 0; j < n; ++j)
        printf("%.9g %.9g %.9g %.9g\n", xyzr[4 * j], xyzr[4 * j + 1], xyzr[4 * j + 2], xyzr[4 * j + 3]);
    } else {
      fprintf(stderr, "Error: morph blend: %s\n", spx_status_string(s));
    }
    free(w), free(c), free(r), free(xyzr);
    spx_free(proxy);
    return s != SPX_C_OK;
  }
  const uint32_t count = (uint32_t)(argc - 2);
  float* w = malloc(sizeof(float) * count);
  float* c = malloc(sizeof(float) * 3 * n);
  float* r = malloc(sizeof(float) * n);
  float* xyzr = malloc(sizeof(float) * 4 * n);
  float* sw = malloc(sizeof(float) * (size_t)sites * count);
  float* normalized = malloc(sizeof(float) * (size_t)sites * count);
  for (uint32_t i = 0; i < count; ++i) w[i] = strtof(argv[i + 2], NULL);
  for (uint32_t site = 0; site < sites; ++site)
    for (uint32_t i = 0; i < count; ++i) sw[(size_t)site * count + i] = w[i];
  int failed = 0;
  printf("# %u spheres, %u poses:", n, p);
  for (uint32_t i = 0; i < p; ++i) printf(" %s", spx_pose_name(proxy, i));
  printf("\n# x y z r\n");
  if ((s = spx_blend_global(proxy, w, count, c, r)) != SPX_C_OK) failed = 1;
  for (uint32_t j = 0; !failed && j < n; ++j) printf("%.9g %.9g %.9g %.9g\n", c[3 * j], c[3 * j + 1], c[3 * j + 2], r[j]);
  if (!failed && (s = spx_blend_global_xyzr(proxy, w, count, xyzr)) != SPX_C_OK) failed = 1;
  for (uint32_t j = 0; !failed && j < n; ++j)
    printf("%.9g %.9g %.9g %.9g\n", xyzr[4 * j], xyzr[4 * j + 1], xyzr[4 * j + 2], xyzr[4 * j + 3]);
  if (!failed && (s = spx_normalize_site_weights(proxy, sw, (size_t)sites * count, normalized)) != SPX_C_OK) failed = 1;
  if (!failed && (s = spx_blend_local_normalized(proxy, normalized, (size_t)sites * count, xyzr)) != SPX_C_OK) failed = 1;
  for (uint32_t j = 0; !failed && j < n; ++j)
    printf("%.9g %.9g %.9g %.9g\n", xyzr[4 * j], xyzr[4 * j + 1], xyzr[4 * j + 2], xyzr[4 * j + 3]);
  if (failed) fprintf(stderr, "Error: blend: %s\n", spx_status_string(s));
  free(w), free(c), free(r), free(xyzr), free(sw), free(normalized);
  spx_free(proxy);
  return failed;
}
