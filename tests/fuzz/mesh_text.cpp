// libFuzzer target: the OFF, PLY, OBJ, STL, COLLADA and .blend checks run before assimp
// (mesh/file_checks.hpp) on arbitrary bytes, read as each format, and a PLY made ready for assimp
// (mesh/ply_input.hpp). Bad input must end in spx::Error with a message of one line, never a
// crash, a read past the text or another exception.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "mesh/file_checks.hpp"
#include "mesh/ply_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (const char* path : {"fuzz.off", "fuzz.ply", "fuzz.obj", "fuzz.stl", "fuzz.dae", "fuzz.blend"}) {
    try {
      spx::check_mesh_text(path, text);
      if (std::string(path) == "fuzz.ply") spx::ply_text_for_assimp(path, text);
    } catch (const spx::Error& e) {
      for (const char c : std::string(e.what()))
        if (static_cast<unsigned char>(c) < 0x20) std::abort();  // the error line would break
    }
  }
  return 0;
}
