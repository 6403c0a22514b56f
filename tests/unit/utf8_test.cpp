#include "core/utf8.h"

#include <gtest/gtest.h>

#include "convoy/engine.pb.h"

namespace convoy {
namespace {

const std::string kReplacement = "\xef\xbf\xbd";

TEST(Utf8, ValidTextIsKept) {
  const std::string text = "plain, caf\xc3\xa9, \xe2\x82\xac, \xf0\x9f\x9a\x97";
  EXPECT_EQ(valid_utf8(text), text);
  EXPECT_EQ(valid_utf8(""), "");
}

TEST(Utf8, BadBytesBecomeReplacementCharacters) {
  EXPECT_EQ(valid_utf8("caf\xe9!"), "caf" + kReplacement + "!");
  EXPECT_EQ(valid_utf8("\xc3"), kReplacement);                     // truncated
  EXPECT_EQ(valid_utf8("\xc0\xaf"), kReplacement + kReplacement);  // overlong '/'
  EXPECT_EQ(valid_utf8("\xed\xa0\x80"), kReplacement + kReplacement + kReplacement);  // surrogate
  EXPECT_EQ(valid_utf8("\xf4\x90\x80\x80").size(), 4 * kReplacement.size());          // > U+10FFFF
}

// Why it matters: an engine's error reply with raw bytes in it cannot be parsed.
TEST(Utf8, AReplyWithARepairedErrorParses) {
  engine::Reply reply;
  reply.set_error(valid_utf8("cannot open '\xff\xfe.sdf'"));
  engine::Reply back;
  ASSERT_TRUE(back.ParseFromString(reply.SerializeAsString()));
  EXPECT_EQ(back.error(), "cannot open '" + kReplacement + kReplacement + ".sdf'");
}

}  // namespace
}  // namespace convoy
