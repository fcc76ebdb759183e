#pragma once
/// @file core/printable.h
/// @brief Text read from a file, made safe to print on a terminal.

#include <cstdio>
#include <string>

namespace lo {

/// @brief `text` with every control character escaped: the C0 controls and
/// DEL as `\xNN`, the C1 controls (U+0080..U+009F, as UTF-8) as `\uNNNN`,
/// every other byte as it is.
///
/// Strings a file supplies (a .vdb's `source_scene_path`, a grid's name, a
/// library's error text quoting either) reach a terminal through messages and
/// reports: printed raw, an ESC or CSI in them recolours, moves the cursor,
/// retitles the window or hides the text after it. Printable input is
/// returned unchanged, so the escapes (themselves printable) survive a second
/// pass. With `keepLineBreaks`, '\n' stays: for a whole message of several
/// lines, whose parts were not escaped one by one.
inline std::string printable(const std::string& text, bool keepLineBreaks = false) {
  std::string out;
  out.reserve(text.size());
  char buf[8];
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && !(keepLineBreaks && c == '\n')) || c == 0x7f) {
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else if (c == 0xc2 && i + 1 < text.size() &&
               static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(text[i + 1]) <= 0x9f) {
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(text[++i]));
      out += buf;
    } else {
      out += char(c);
    }
  }
  return out;
}

}  // namespace lo
