// HtmlEscape against the entities HTML 5 defines for the four characters it replaces.
#include "measurement/html_text.hpp"

#include <gtest/gtest.h>

namespace ftstack {
namespace {

TEST(HtmlText, EscapesTheFourMarkupCharacters) {
  EXPECT_EQ(HtmlEscape(R"(<a href="x">&</a>)"), "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;");
}

TEST(HtmlText, LeavesOtherTextAndUtf8Alone) {
  EXPECT_EQ(HtmlEscape("Fz 1.5 N·m ± 2 % 'q'"), "Fz 1.5 N·m ± 2 % 'q'");
  EXPECT_EQ(HtmlEscape(""), "");
}

TEST(HtmlText, AnEntityIsEscapedAgainNotPassedThrough) {
  EXPECT_EQ(HtmlEscape("&amp;"), "&amp;amp;");
}

}  // namespace
}  // namespace ftstack
