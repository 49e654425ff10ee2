#include "codec/status.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace geomip::codec {
namespace {

TEST(Status, EveryCodeHasADistinctMessage) {
  std::set<std::string> messages;
  for (int i = 0; i < kStatusCount; ++i) {
    const std::string m(status_message(static_cast<Status>(i)));
    EXPECT_FALSE(m.empty()) << "status " << i << " has no message";
    EXPECT_TRUE(messages.insert(m).second) << "status " << i << " repeats message '" << m << "'";
  }
}

TEST(Status, CountMatchesTheEnum) {
  // The last enumerator must be kStatusCount - 1: a code added without updating the count fails here.
  EXPECT_EQ(static_cast<int>(Status::kInvalidArgument), kStatusCount - 1);
  EXPECT_TRUE(status_message(static_cast<Status>(kStatusCount)).empty());
}

// Error messages reach a terminal as one line: control bytes and invalid UTF-8 (garbage a parser quotes)
// become '?', valid UTF-8 (a user's file name) stays, long messages are cut at a character boundary.
TEST(OneLine, KeepsUtf8AndReplacesControlAndInvalidBytes) {
  EXPECT_EQ(one_line("b\xc3\xbcste.obj: empty file"), "b\xc3\xbcste.obj: empty file");
  EXPECT_EQ(one_line("a\nb\tc\x1b[31m\x7f"), "a?b?c?[31m?");
  EXPECT_EQ(one_line("\xff\xfe"), "??");
  EXPECT_EQ(one_line("\xc0\x80"), "??");                              // overlong NUL
  EXPECT_EQ(one_line("\xed\xa0\x80"), "???");                         // UTF-16 surrogate
  EXPECT_EQ(one_line("x\xe2\x82"), "x??");                            // truncated at the end
  EXPECT_EQ(one_line("\xf0\x9f\x98\x80 ok"), "\xf0\x9f\x98\x80 ok");  // 4-byte character
  EXPECT_EQ(one_line("\xf4\x90\x80\x80"), "????");                    // above U+10FFFF
  EXPECT_EQ(one_line(std::string(10, 'a'), 4), "aaaa...");
  EXPECT_EQ(one_line("\xc3\xbc\xc3\xbc\xc3\xbc", 3), "\xc3\xbc\xc3\xbc...");  // never splits a character
}

}  // namespace
}  // namespace geomip::codec
