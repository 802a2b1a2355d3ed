#include "core/version.hpp"

namespace spx {

const char* version_string() { return SPX_VERSION; }

}  // namespace spx
