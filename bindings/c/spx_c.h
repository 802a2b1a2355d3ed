/* spx_c.h - the runtime reader as a C API (libspx_c): for C hosts and for C#, Rust, Python and
 * other languages that bind to C. The same loader and blends as spx_runtime.h, behind an
 * opaque handle. Every function that can fail returns a status (0 = ok; spx_status_string()
 * names it); the numbers are those of spx::Status in spx_runtime.h.
 *
 *   spx_proxy* proxy = NULL;
 *   if (spx_load_file("car.spx", &proxy) != SPX_C_OK) ...
 *   spx_blend_global_xyzr(proxy, weights, spx_pose_count(proxy), xyzr);   (each frame)
 *   spx_free(proxy);
 *
 * Thread safety: blends take a const handle and may run on many threads at once; loading and
 * spx_free need exclusive access to their handle. */
#ifndef SPX_C_H
#define SPX_C_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SPX_C_OK 0

/* Exported from libspx_c (built with hidden visibility otherwise). */
#if defined(SPX_C_BUILD) && defined(__GNUC__)
#define SPX_C_API __attribute__((visibility("default")))
#else
#define SPX_C_API
#endif

typedef struct spx_proxy spx_proxy;

/* On success *out is a new handle (free it with spx_free); on failure *out is NULL. */
SPX_C_API int spx_load_file(const char* path, spx_proxy** out);
SPX_C_API int spx_load_memory(const void* data, size_t size, spx_proxy** out);
SPX_C_API void spx_free(spx_proxy* proxy);
SPX_C_API const char* spx_status_string(int status);

SPX_C_API uint32_t spx_sphere_count(const spx_proxy* proxy);
SPX_C_API uint32_t spx_pose_count(const spx_proxy* proxy);
SPX_C_API uint32_t spx_site_count(const spx_proxy* proxy);
/* x y z r per sphere of `pose`; NULL when out of range. Valid until spx_free. */
SPX_C_API const float* spx_pose_spheres(const spx_proxy* proxy, uint32_t pose);
SPX_C_API const char* spx_pose_name(const spx_proxy* proxy, uint32_t pose);
SPX_C_API const uint32_t* spx_sphere_sites(const spx_proxy* proxy);
SPX_C_API const float* spx_site_positions(const spx_proxy* proxy);

/* The blends; see spx_runtime.h for the weights policy. */
SPX_C_API int spx_blend_global(const spx_proxy* proxy, const float* weights, uint32_t weight_count, float* centers,
                     float* radii);
SPX_C_API int spx_blend_local(const spx_proxy* proxy, const float* site_weights, size_t weight_count, float* centers,
                    float* radii);
SPX_C_API int spx_blend_global_xyzr(const spx_proxy* proxy, const float* weights, uint32_t weight_count, float* xyzr);
/* A morph-target body: one weight per example after the rest (spx_pose_count - 1), added as the
 * mesh adds its morph targets (spx::blend_morph). */
SPX_C_API int spx_blend_morph(const spx_proxy* proxy, const float* weights, uint32_t weight_count, float* centers,
                    float* radii);
SPX_C_API int spx_blend_morph_xyzr(const spx_proxy* proxy, const float* weights, uint32_t weight_count, float* xyzr);
SPX_C_API int spx_normalize_site_weights(const spx_proxy* proxy, const float* site_weights, size_t weight_count,
                               float* normalized);
SPX_C_API int spx_blend_local_normalized(const spx_proxy* proxy, const float* normalized, size_t weight_count, float* xyzr);
/* A rigged body's proxy: its joints (0 without a skin) and the skin, as spx::skin in
 * spx_runtime.h: joint_count column-major 4x4 matrices in, x y z r per sphere out. */
SPX_C_API uint32_t spx_joint_count(const spx_proxy* proxy);
SPX_C_API const char* spx_joint_name(const spx_proxy* proxy, uint32_t joint);
SPX_C_API int32_t spx_joint_parent(const spx_proxy* proxy, uint32_t joint);
SPX_C_API int spx_skin(const spx_proxy* proxy, const float* joint_matrices, int joint_count, float* xyzr);

#ifdef __cplusplus
}
#endif

#endif /* SPX_C_H */
