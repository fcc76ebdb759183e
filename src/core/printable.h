#pragma once
/// @file core/printable.h
/// @brief Text read from a file, made safe to print on a terminal.

#include <cstdio>
#include <string>

namespace lo {

/// How many bytes the well-formed UTF-8 character at `text[i]` (a byte from
/// 0x80) takes, or 0 (RFC 3629: no overlong form, surrogate or code beyond
/// U+10FFFF).
inline size_t utf8Length(const std::string& text, size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  size_t n = 0;
  unsigned char low = 0x80, high = 0xbf;  // the second byte's range
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
  } else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    if (c == 0xe0) low = 0xa0;
    if (c == 0xed) high = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    if (c == 0xf0) low = 0x90;
    if (c == 0xf4) high = 0x8f;
  }
  if (n == 0 || i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    const auto b = static_cast<unsigned char>(text[i + k]);
    if (b < (k == 1 ? low : 0x80) || b > (k == 1 ? high : 0xbf)) return 0;
  }
  return n;
}

/// @brief `text` with every control character escaped: the C0 controls and
/// DEL as `\xNN`, the C1 controls (U+0080..U+009F, as UTF-8) as `\uNNNN`,
/// every byte that is not part of a well-formed UTF-8 character (a Latin-1
/// file's 0xE9, a UTF-16 file's 0xFF) as `\xNN`, the rest as it is.
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
    } else if (c >= 0x80) {
      const size_t n = utf8Length(text, i);
      if (n == 0) {
        std::snprintf(buf, sizeof buf, "\\x%02x", c);
        out += buf;
      } else {
        out.append(text, i, n);
        i += n - 1;
      }
    } else {
      out += char(c);
    }
  }
  return out;
}

/// printable(text), cut to at most `most` bytes with "..." where it was
/// longer (never inside a UTF-8 character or an escape): a name quoted in a
/// message, which a file may make 100,000 characters long (H16-4-4).
inline std::string printableShort(const std::string& text, size_t most = 60) {
  const std::string whole = printable(text);
  if (whole.size() <= most) return whole;
  size_t end = most - 3;
  while (end > 0 && (static_cast<unsigned char>(whole[end]) & 0xc0) == 0x80) --end;
  // An escape (\xNN, \uNNNN) is not split: cut before its backslash.
  const size_t slash = whole.rfind('\\', end);
  if (slash != std::string::npos && end - slash < 6) end = slash;
  return whole.substr(0, end) + "...";
}

}  // namespace lo
