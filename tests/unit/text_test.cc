// Escaping for the context a string from a message or a session folder
// lands in (docs/security.md "Text from messages and folders"), with the
// strings that once broke the report, the compare page and the monitor.
#include "rms/base/text.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <string>

#include "rms/report/report.h"

namespace rms {
namespace {

const char* const kHostile[] = {"<!--<script>", "</script><script>alert(1)</script>",
                                "\"><img src=x onerror=alert(1)>", "a'b", "x&amp;y"};

TEST(Text, HtmlTextLeavesNoMarkupAndNoWayOutOfAnAttribute) {
  for (const char* s : kHostile) {
    const std::string h = HtmlText(s);
    EXPECT_EQ(h.find_first_of("<>\"'"), std::string::npos) << h;
  }
  EXPECT_EQ(HtmlText("x&amp;y"), "x&amp;amp;y");
  EXPECT_EQ(HtmlText("plain text, 1.5 ft"), "plain text, 1.5 ft");
}

TEST(Text, ScriptJsonCannotEndTheScriptOpenACommentOrEndALine) {
  for (const char* s : kHostile) {
    const nlohmann::json j = {{"name", s},
                              {"line",
                               "a\xE2\x80\xA8"
                               "b\xE2\x80\xA9"
                               "c"}};
    const std::string text = report::ScriptJson(j);
    EXPECT_EQ(text.find_first_of("<>&"), std::string::npos) << text;
    EXPECT_EQ(text.find("\xE2\x80\xA8"), std::string::npos) << text;
    EXPECT_EQ(text.find("\xE2\x80\xA9"), std::string::npos) << text;
    EXPECT_EQ(nlohmann::json::parse(text), j) << "reads back the same";
  }
}

TEST(Text, CsvFieldQuotesWhatWouldSplitARowAndKeepsFormulasText) {
  EXPECT_EQ(CsvField("plain"), "plain");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(CsvField("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(CsvField("cr\rhere"), "\"cr\rhere\"");
  EXPECT_EQ(CsvField("=HYPERLINK(\"x\")"), "\"'=HYPERLINK(\"\"x\"\")\"");
  EXPECT_EQ(CsvField("@SUM(A1)"), "'@SUM(A1)");
  EXPECT_EQ(CsvField("+cmd"), "'+cmd");
  EXPECT_EQ(CsvField("-1.5"), "-1.5") << "a number stays a number";
  EXPECT_EQ(CsvField("+2e3"), "+2e3");
  EXPECT_EQ(CsvField("-x"), "'-x");
}

TEST(Text, TerminalTextShowsControlCharactersInsteadOfObeyingThem) {
  const std::string clear = "\x1b[2J\x1b[H", title = "\x1b]0;owned\x07",
                    c1 = "\xC2\x9B"
                         "31m";
  EXPECT_EQ(TerminalText(clear), "\\x1b[2J\\x1b[H");
  EXPECT_EQ(TerminalText(title), "\\x1b]0;owned\\x07");
  EXPECT_EQ(TerminalText(c1), "\\u009b31m");
  EXPECT_EQ(TerminalText("line\tone\nline two\r"), "line\tone\nline two\\x0d");
  EXPECT_EQ(TerminalText("caf\xC3\xA9 \xE2\x82\xAC"), "caf\xC3\xA9 \xE2\x82\xAC") << "UTF-8 kept";
  EXPECT_EQ(TerminalText("\x7f"), "\\x7f");
}

}  // namespace
}  // namespace rms
