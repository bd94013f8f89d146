// Text taken from input and quoted in messages and files stays valid UTF-8: a quoted character is whole
// (never half of a multi-byte one), an excerpt is cut at a character boundary, and bytes that are not
// UTF-8 are written as \xNN. Header-only, so that everything built from core's sources alone (the
// built-in algorithms' plugin builds) has it too.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace growbench {

// The length of the well-formed UTF-8 character starting at s[i] (1 to 4), or 0 when the bytes there
// are not one: a stray continuation byte, a truncated sequence, an overlong form, a surrogate, or a
// code point above U+10FFFF (RFC 3629).
inline std::size_t utf8_char_length(std::string_view s, std::size_t i) {
  if (i >= s.size()) return 0;
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the range of the second byte (tighter for some lead bytes)
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;  // overlong
    if (c == 0xED) hi = 0x9F;  // surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;  // overlong
    if (c == 0xF4) hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;
  }
  if (i + n > s.size() || b(1) < lo || b(1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (b(k) < 0x80 || b(k) > 0xBF) return 0;
  return n;
}

// `text` with every byte that is not part of a well-formed character, and every control character but
// newline and tab, written as \xNN: valid UTF-8 that prints as one line per line of the input. With
// `one_line`, newline and tab too: text that cannot end the line (or the comment) it is written into.
inline std::string escape_utf8(std::string_view text, bool one_line = false) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_char_length(text, i);
    const auto c = static_cast<unsigned char>(text[i]);
    const bool kept_space = !one_line && (c == '\n' || c == '\t');
    if (n == 0 || (n == 1 && ((c < 0x20 && !kept_space) || c == 0x7f))) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

// The character at text[i], whole, for a message ("found 'é'"); a byte that starts no character is \xNN.
inline std::string utf8_char_at(std::string_view text, std::size_t i) {
  if (i >= text.size()) return {};
  const std::size_t n = utf8_char_length(text, i);
  return escape_utf8(text.substr(i, n == 0 ? 1 : n));
}

// At most `max_bytes` of `text`, cut at a character boundary, then escaped; "..." marks a cut.
inline std::string utf8_excerpt(std::string_view text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return escape_utf8(text);
  std::size_t end = 0;
  while (end < text.size()) {
    const std::size_t n = utf8_char_length(text, end);
    const std::size_t step = n == 0 ? 1 : n;
    if (end + step > max_bytes) break;
    end += step;
  }
  return escape_utf8(text.substr(0, end)) + "...";
}

// Whether `text` holds an ASCII control character (a line break, a tab, an escape): what ends a line or a
// comment that a name or path is written into.
inline bool has_control_char(std::string_view text) {
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return true;
  return false;
}

// Why `text` cannot be a name that files, folders, renders and reports carry (a suite's or scene's name, an
// entry's label), or "" when it can: at most kMaxNameBytes, and no control character (a line break ended
// the comment a name was written into).
inline constexpr std::size_t kMaxNameBytes = 100;
inline std::string name_problem(std::string_view text) {
  if (text.size() > kMaxNameBytes)
    return "expected a name of at most " + std::to_string(kMaxNameBytes) + " bytes, got " + std::to_string(text.size());
  if (has_control_char(text))
    return "expected a name without control characters (a line break, a tab), got '" + escape_utf8(text, true) + "'";
  return {};
}

// Whether the whole of `text` is well-formed UTF-8.
inline bool is_valid_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_char_length(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

// The UTF-8 byte order mark some editors write at the top of a file; readers skip it.
inline constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

}  // namespace growbench
