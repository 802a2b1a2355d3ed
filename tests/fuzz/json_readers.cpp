// libFuzzer target: the spheres, proxy and skin readers on arbitrary text. Bad input must end in
// spx::Error (what the tools turn into one error line), never a crash or another exception.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "io/spheres_file.hpp"
#include "io/proxy_file.hpp"
#include "io/skin_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  spx::json j;
  try {
    j = spx::json::parse(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const spx::json::exception&) {
    return 0;  // read_json_file reports these as "not valid JSON"
  }
  for (int reader = 0; reader < 3; ++reader) {
    try {
      if (reader == 0) {
        const spx::SpheresFile f = spx::spheres_from_json(j, "fuzz.json");
        for (const auto& s : f.spheres)
          if (!(s.radius > 0)) std::abort();
      } else if (reader == 1) {
        const spx::ProxyModel p = spx::proxy_from_json(j, "fuzz.json");
        for (int site : p.sphere_sites)
          if (site < 0 || size_t(site) >= p.sites.size()) std::abort();
      } else {
        // Every joint a skin reader lets through reaches a root, and every weight names a joint.
        const spx::SkinFile skin = spx::skin_from_json(j, "fuzz.json");
        for (size_t k = 0; k < skin.joints.size(); ++k) {
          int up = int(k);
          for (size_t steps = 0; up != -1 && steps <= skin.joints.size(); ++steps) up = skin.joints[size_t(up)].parent;
          if (up != -1) std::abort();
        }
        for (const spx::JointWeights& w : skin.vertex_weights)
          for (const auto& [joint, weight] : w)
            if (joint < 0 || size_t(joint) >= skin.joints.size()) std::abort();
      }
    } catch (const spx::Error&) {
    } catch (const spx::json::exception&) {
      if (reader == 0) std::abort();  // the spheres reader must classify everything itself
    }
  }
  return 0;
}
