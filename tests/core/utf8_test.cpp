#include "core/utf8.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace growbench {
namespace {

TEST(Utf8, CharacterLengthsFollowRfc3629) {
  EXPECT_EQ(utf8_char_length("a", 0), 1u);
  EXPECT_EQ(utf8_char_length("\xC3\xA9", 0), 2u);          // é
  EXPECT_EQ(utf8_char_length("\xE2\x82\xAC", 0), 3u);      // €
  EXPECT_EQ(utf8_char_length("\xF0\x9F\x8C\xB1", 0), 4u);  // 🌱
  EXPECT_EQ(utf8_char_length("\xC3", 0), 0u);              // half of é
  EXPECT_EQ(utf8_char_length("\xA9", 0), 0u);              // a continuation byte alone
  EXPECT_EQ(utf8_char_length("\xC0\xAF", 0), 0u);          // overlong '/'
  EXPECT_EQ(utf8_char_length("\xE0\x80\xAF", 0), 0u);      // overlong '/'
  EXPECT_EQ(utf8_char_length("\xED\xA0\x80", 0), 0u);      // a surrogate
  EXPECT_EQ(utf8_char_length("\xF4\x90\x80\x80", 0), 0u);  // above U+10FFFF
  EXPECT_EQ(utf8_char_length("\xFF", 0), 0u);
}

TEST(Utf8, EscapingKeepsCharactersWholeAndWritesBadBytesAsHex) {
  EXPECT_EQ(escape_utf8("F\xC3\xA9G"), "F\xC3\xA9G");
  EXPECT_EQ(escape_utf8("F\xC3"), "F\\xc3");
  EXPECT_EQ(escape_utf8(std::string("a\0b\x1b[31m\n\tc", 11)), "a\\x00b\\x1b[31m\n\tc");
  EXPECT_EQ(utf8_char_at("F\xC3\xA9G", 1), "\xC3\xA9");
  EXPECT_EQ(utf8_char_at("F\xC3", 1), "\\xc3");
  // Cut at a character boundary: the euro sign does not fit in 4 bytes after "ab".
  EXPECT_EQ(utf8_excerpt("ab\xE2\x82\xACgh", 4), "ab...");
  EXPECT_EQ(utf8_excerpt("ab\xE2\x82\xACgh", 5), "ab\xE2\x82\xAC...");
  EXPECT_EQ(utf8_excerpt("abc", 3), "abc");
  EXPECT_TRUE(is_valid_utf8("F\xC3\xA9"));
  EXPECT_FALSE(is_valid_utf8("F\xC3"));
}

// Every InputError's message is valid UTF-8, whatever it quotes: a journal can always store it.
TEST(Utf8, ErrorMessagesAreAlwaysValidUtf8) {
  const InputError e(std::string("g.lsys:3:6: expected a symbol, found '\xC3'"));
  EXPECT_STREQ(e.what(), "g.lsys:3:6: expected a symbol, found '\\xc3'");
  EXPECT_NO_THROW((void)nlohmann::json(e.what()).dump());
  const OutOfMemoryError oom("out of memory \xFF");
  EXPECT_STREQ(oom.what(), "out of memory \\xff");
  const std::bad_alloc& as_bad_alloc = oom;  // handlers of allocation failure see it as one
  EXPECT_STREQ(as_bad_alloc.what(), "out of memory \\xff");
}

}  // namespace
}  // namespace growbench
