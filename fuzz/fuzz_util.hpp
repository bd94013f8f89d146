// What every fuzz target shares: the input as a file, for entry points that take a path, and the rule
// the targets check. Input may make the project throw InputError, its documented error for bad input
// (the CLI's exit status 2), and nothing else: any other exception escapes the target and libFuzzer
// reports it, as it reports a sanitizer's finding. An InputError's message quotes the input, and a suite
// writes it into its journal as JSON, so it must be valid UTF-8 (the project escapes invalid bytes).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace growbench::fuzz {

// This process's own directory for input files, removed when the process exits normally (a crash leaves
// it, with the input that crashed beside libFuzzer's copy).
inline const std::filesystem::path& work_dir() {
  static const std::filesystem::path dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "growbench-fuzz.XXXXXX").string();
    if (!mkdtemp(pattern.data())) {
      std::perror("growbench fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] { std::filesystem::remove_all(work_dir()); });
    return std::filesystem::path(pattern);
  }();
  return dir;
}

// Writes `data` to the file `name` in work_dir() (the name's extension matters to some readers) and
// returns its path.
inline std::string write_input(std::string_view name, const std::uint8_t* data, std::size_t size) {
  const std::string path = (work_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "growbench fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// Whether `s` is well-formed UTF-8 (RFC 3629: no overlong forms, surrogates or code points past U+10FFFF).
inline bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the first continuation byte
    if (c < 0x80) {
      ++i;
      continue;
    } else if (c >= 0xC2 && c <= 0xDF) {
      n = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 2;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 3;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return false;
    }
    if (i + n >= s.size()) return false;  // cut short
    for (std::size_t k = 1; k <= n; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xBF)) return false;
    }
    i += n + 1;
  }
  return true;
}

// GROWBENCH_FUZZ_IGNORE_UTF8=1 lets a message with invalid UTF-8 pass: a fuzzing campaign can then look
// past that one class of finding, which every reader has while the input it quotes is not escaped.
inline bool ignore_utf8() {
  static const bool ignore = [] {
    const char* v = std::getenv("GROWBENCH_FUZZ_IGNORE_UTF8");
    return v && std::string_view(v) == "1";
  }();
  return ignore;
}

// Runs `f`, which reads the input; an InputError is the expected answer to bad input, provided its
// message is valid UTF-8. Anything else escapes to libFuzzer.
template <class F>
void expect_input_errors(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    if (!ignore_utf8() && !valid_utf8(e.what())) {
      std::fprintf(stderr, "growbench fuzz: an InputError's message is not valid UTF-8: %s\n", e.what());
      std::abort();
    }
  }
}

}  // namespace growbench::fuzz
