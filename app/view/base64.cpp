#include "view/base64.hpp"

namespace gvio::view {

void appendBase64(std::string& out, std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(bytes[i]); };
  const std::size_t start = out.size();
  out.resize(start + (bytes.size() + 2) / 3 * 4);
  char* o = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const unsigned v = (byte(i) << 16U) | (byte(i + 1) << 8U) | byte(i + 2);
    *o++ = kAlphabet[(v >> 18U) & 63U];
    *o++ = kAlphabet[(v >> 12U) & 63U];
    *o++ = kAlphabet[(v >> 6U) & 63U];
    *o++ = kAlphabet[v & 63U];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest == 0) return;
  const unsigned v = (byte(i) << 16U) | (rest == 2 ? byte(i + 1) << 8U : 0U);
  *o++ = kAlphabet[(v >> 18U) & 63U];
  *o++ = kAlphabet[(v >> 12U) & 63U];
  *o++ = rest == 2 ? kAlphabet[(v >> 6U) & 63U] : '=';
  *o = '=';
}

}  // namespace gvio::view
