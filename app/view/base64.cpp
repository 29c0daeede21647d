#include "view/base64.hpp"

namespace gvio::view {

void appendBase64(std::string& out, std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(bytes[i]); };
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const unsigned v = (byte(i) << 16U) | (byte(i + 1) << 8U) | byte(i + 2);
    out += kAlphabet[(v >> 18U) & 63U];
    out += kAlphabet[(v >> 12U) & 63U];
    out += kAlphabet[(v >> 6U) & 63U];
    out += kAlphabet[v & 63U];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest == 0) return;
  const unsigned v = (byte(i) << 16U) | (rest == 2 ? byte(i + 1) << 8U : 0U);
  out += kAlphabet[(v >> 18U) & 63U];
  out += kAlphabet[(v >> 12U) & 63U];
  out += rest == 2 ? kAlphabet[(v >> 6U) & 63U] : '=';
  out += '=';
}

}  // namespace gvio::view
