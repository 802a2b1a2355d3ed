#include "core/version.hpp"

#include <elf.h>
#include <link.h>

#include <cstddef>
#include <cstdio>
#include <cstring>

namespace spx {

const char* version_string() { return SPX_VERSION; }

namespace {

// The first object dl_iterate_phdr gives is the program itself: its PT_NOTE segments' GNU build
// ID note, in hex.
int program_build_id(dl_phdr_info* info, size_t, void* data) {
  auto* out = static_cast<std::string*>(data);
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& segment = info->dlpi_phdr[i];
    if (segment.p_type != PT_NOTE) continue;
    const char* p = reinterpret_cast<const char*>(info->dlpi_addr + segment.p_vaddr);
    const char* end = p + segment.p_memsz;
    while (end - p >= std::ptrdiff_t(sizeof(ElfW(Nhdr)))) {
      const auto* note = reinterpret_cast<const ElfW(Nhdr)*>(p);
      const char* name = p + sizeof(ElfW(Nhdr));
      const char* desc = name + ((note->n_namesz + 3) & ~3u);
      if (note->n_type == NT_GNU_BUILD_ID && note->n_namesz == 4 && std::memcmp(name, "GNU", 4) == 0) {
        for (unsigned k = 0; k < note->n_descsz; ++k) {
          char hex[3];
          std::snprintf(hex, sizeof hex, "%02x", static_cast<unsigned char>(desc[k]));
          *out += hex;
        }
        return 1;
      }
      p = desc + ((note->n_descsz + 3) & ~3u);
    }
  }
  return 1;
}

}  // namespace

const std::string& build_identity() {
  static const std::string id = [] {
    std::string out;
    dl_iterate_phdr(program_build_id, &out);
    return out;
  }();
  return id;
}

}  // namespace spx
