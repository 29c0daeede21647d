#pragma once
// Base64 (RFC 4648 section 4, with padding): how the viewer's data files carry binary arrays
// inside JavaScript, so that the page also works opened from the folder (file://, where a page
// may load scripts but not fetch files).
#include <cstddef>
#include <string>
#include <string_view>

namespace gvio::view {

// Appends the encoding of `bytes` to `out`.
void appendBase64(std::string& out, std::string_view bytes);

}  // namespace gvio::view
