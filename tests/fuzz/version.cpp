// The fuzz targets link a few library sources without the CLI shell that defines this.
namespace spx {
const char* version_string() { return "fuzz"; }
}  // namespace spx
