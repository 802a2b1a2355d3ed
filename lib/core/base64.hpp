#pragma once
// Base64 (RFC 4648, with padding): glTF's data: URIs and the arrays the proxy page carries.
#include <optional>
#include <string>

namespace spx {

std::string encode_base64(const void* data, size_t bytes);
// nullopt when `text` holds a character outside the alphabet (padding ends it).
std::optional<std::string> decode_base64(const std::string& text);

}  // namespace spx
