// The Python module `spx` (pybind11): load a .spx, read its poses, blend; arrays are numpy.
//   import spx
//   proxy = spx.load("car.spx")
//   proxy.pose_names, proxy.pose(2)            # (n, 4) float32: x y z r
//   proxy.blend_global([0.5, 0.5, 0, 0, 0])    # (n, 4)
//   proxy.blend_local(site_weights)            # site_weights: (site_count, pose_count)
//   proxy.skin(M)                              # M: (joint_count, 4, 4), M[j] @ [x, y, z, 1]
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "spx_runtime.h"

namespace py = pybind11;

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

void check(spx::Status s, const std::string& what) {
  if (s != spx::SPX_OK) throw py::value_error(what + ": " + spx::status_string(s));
}

// What `get` gives for 0..count-1, as a Python list.
template <class Get>
auto list_of(uint32_t count, Get get) -> std::vector<decltype(get(0u))> {
  std::vector<decltype(get(0u))> out;
  for (uint32_t i = 0; i < count; ++i) out.push_back(get(i));
  return out;
}

py::array_t<float> rows(const float* data, size_t count, size_t width) {
  py::array_t<float> out({count, width});
  std::copy(data, data + count * width, out.mutable_data());
  return out;
}

}  // namespace

PYBIND11_MODULE(spx, m) {
  m.doc() = "Sphere-union collision proxies (.spx): load, read the poses, blend.";
  py::class_<spx::Proxy>(m, "Proxy")
      .def_property_readonly("sphere_count", &spx::Proxy::sphere_count)
      .def_property_readonly("pose_count", &spx::Proxy::pose_count)
      .def_property_readonly("site_count", &spx::Proxy::site_count)
      .def_property_readonly("pose_names",
                             [](const spx::Proxy& p) {
                               return list_of(p.pose_count(), [&](uint32_t i) { return std::string(p.pose_name(i)); });
                             })
      .def(
          "pose",
          [](const spx::Proxy& p, uint32_t i) {
            if (i >= p.pose_count()) throw py::index_error("no pose " + std::to_string(i));
            return rows(p.pose_spheres(i), p.sphere_count(), 4);
          },
          "x y z r of every sphere of pose i, shape (sphere_count, 4)")
      .def_property_readonly("sphere_sites",
                             [](const spx::Proxy& p) {
                               py::array_t<uint32_t> out(p.sphere_count());
                               std::copy(p.sphere_sites(), p.sphere_sites() + p.sphere_count(), out.mutable_data());
                               return out;
                             })
      .def_property_readonly("site_positions", [](const spx::Proxy& p) { return rows(p.site_positions(), p.site_count(), 3); })
      .def(
          "blend_global",
          [](const spx::Proxy& p, const FloatArray& weights) {
            py::array_t<float> out({size_t(p.sphere_count()), size_t(4)});
            check(spx::blend_global_xyzr(p, weights.data(), uint32_t(weights.size()), out.mutable_data()), "blend_global");
            return out;
          },
          py::arg("weights"), "One weight per pose; returns x y z r per sphere, shape (sphere_count, 4)")
      .def(
          "blend_morph",
          [](const spx::Proxy& p, const FloatArray& weights) {
            py::array_t<float> out({size_t(p.sphere_count()), size_t(4)});
            check(spx::blend_morph_xyzr(p, weights.data(), uint32_t(weights.size()), out.mutable_data()), "blend_morph");
            return out;
          },
          py::arg("weights"),
          "A morph-target body: one weight per example after the rest, added as the mesh adds its morph targets; "
          "returns x y z r per sphere, shape (sphere_count, 4)")
      .def(
          "blend_local",
          [](const spx::Proxy& p, const FloatArray& site_weights) {
            std::vector<float> normalized(size_t(site_weights.size()));
            check(spx::normalize_site_weights(p, site_weights.data(), size_t(site_weights.size()), normalized.data()),
                  "blend_local");
            py::array_t<float> out({size_t(p.sphere_count()), size_t(4)});
            check(spx::blend_local_normalized(p, normalized.data(), normalized.size(), out.mutable_data()), "blend_local");
            return out;
          },
          py::arg("site_weights"), "pose_count weights per blend site, shape (site_count, pose_count)")
      .def_property_readonly("joint_count", &spx::Proxy::joint_count)
      .def_property_readonly("joint_names",
                             [](const spx::Proxy& p) {
                               return list_of(p.joint_count(), [&](uint32_t j) { return std::string(p.joint_name(j)); });
                             })
      .def_property_readonly("joint_parents",
                             [](const spx::Proxy& p) {
                               return list_of(p.joint_count(), [&](uint32_t j) { return int(p.joint_parent(j)); });
                             })
      .def(
          "skin",
          [](const spx::Proxy& p, const FloatArray& matrices) {
            if (matrices.ndim() != 3 || matrices.shape(1) != 4 || matrices.shape(2) != 4)
              throw py::value_error("skin: joint matrices must have shape (joint_count, 4, 4)");
            // Ordinary (row-major) matrices in, column-major as the runtime takes them.
            const size_t joints = size_t(matrices.shape(0));
            std::vector<float> m(joints * 16);
            const float* in = matrices.data();
            for (size_t j = 0; j < joints; ++j)
              for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) m[j * 16 + size_t(c * 4 + r)] = in[j * 16 + size_t(r * 4 + c)];
            py::array_t<float> out({size_t(p.sphere_count()), size_t(4)});
            check(spx::skin(p, m.data(), int(joints), out.mutable_data()), "skin");
            return out;
          },
          py::arg("matrices"),
          "The spheres of a rigged body in one frame: matrices (joint_count, 4, 4), each joint's global transform "
          "times its inverse bind (M[j] @ [x, y, z, 1]); returns x y z r per sphere, shape (sphere_count, 4)");
  m.def(
      "load",
      [](const std::string& path) {
        spx::Proxy proxy;
        check(spx::load_file(path.c_str(), &proxy), path);
        return proxy;
      },
      py::arg("path"), "Loads a .spx file; ValueError naming the file and the problem otherwise");
}
