// base/utf8.h against hand-checked byte sequences (RFC 3629's table of well-formed sequences).
#include "base/utf8.h"

#include <gtest/gtest.h>

#include <string>

namespace isolink {
namespace {

constexpr size_t kNone = std::string::npos;

TEST(Utf8, AcceptsWellFormedText) {
  EXPECT_EQ(invalid_utf8_at(""), kNone);
  EXPECT_EQ(invalid_utf8_at("xfmr-12m"), kNone);
  EXPECT_EQ(invalid_utf8_at("Pr\xC3\xBC"
                            "fung"),
            kNone);                                       // U+00FC, 2 bytes
  EXPECT_EQ(invalid_utf8_at("\xE2\x82\xAC"), kNone);      // U+20AC, 3 bytes
  EXPECT_EQ(invalid_utf8_at("\xF0\x9F\x98\x80"), kNone);  // U+1F600, 4 bytes
  EXPECT_EQ(invalid_utf8_at("\xF4\x8F\xBF\xBF"), kNone);  // U+10FFFF, the last
}

TEST(Utf8, FindsTheFirstBadByte) {
  EXPECT_EQ(invalid_utf8_at("name\xFF"), 4u);          // never valid
  EXPECT_EQ(invalid_utf8_at("ab\xC0\x80"), 2u);        // overlong NUL
  EXPECT_EQ(invalid_utf8_at("\xE0\x80\x80"), 0u);      // overlong 3-byte
  EXPECT_EQ(invalid_utf8_at("x\xED\xA0\x80"), 1u);     // surrogate U+D800
  EXPECT_EQ(invalid_utf8_at("\xF4\x90\x80\x80"), 0u);  // above U+10FFFF
  EXPECT_EQ(invalid_utf8_at("\xE2\x82"), 0u);          // cut short
  EXPECT_EQ(invalid_utf8_at("ok\x80"), 2u);            // a lone continuation byte
  EXPECT_EQ(invalid_utf8_at("\xC3\xBC\xC3"), 2u);      // good, then cut short
}

}  // namespace
}  // namespace isolink
