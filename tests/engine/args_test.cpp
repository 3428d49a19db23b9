// Declared options (engine::core::OptionSpec): --help is made from the
// declarations, and a read that disagrees with its declaration is caught.
#include <gtest/gtest.h>

#include <stdexcept>

#include "engine/core/args.h"

namespace {

using engine::core::Args;
using engine::core::HelpRequested;
using engine::core::OptionSpec;

std::vector<OptionSpec> specs() {
  return {
      {"width", "W", "320", "image width in pixels", std::pair{1.0, 16384.0}, {}, false},
      {"pass", "WORD", "full", "what is written", std::nullopt, {"full", "gi"}, false},
      {"out", "PATH", "", "the file written", std::nullopt, {}, false},
      {"quiet", "", "", "say nothing", std::nullopt, {}, true},
  };
}

TEST(Args, HelpListsEveryDeclaredOptionWithItsRangeAndDefault) {
  try {
    const Args args("render", {"--width", "5", "--help"}, specs(), "usage: render\n");
    FAIL() << "--help did not stop the parse";
  } catch (const HelpRequested& e) {
    EXPECT_TRUE(e.complete());
    const std::string text = e.what();
    EXPECT_EQ(text.rfind("usage: render\n", 0), 0u);
    EXPECT_NE(text.find("--width W"), std::string::npos);
    EXPECT_NE(text.find("image width in pixels [1..16384; default 320]"), std::string::npos);
    EXPECT_NE(text.find("what is written [full|gi; default full]"), std::string::npos);
    EXPECT_NE(text.find("the file written [required]"), std::string::npos);
    EXPECT_NE(text.find("--quiet "), std::string::npos);
    EXPECT_EQ(text.find("--quiet ["), std::string::npos) << "a flag has no value, range or default";
  }
}

TEST(Args, DeclaredReadsParseAndBadValuesNameTheOption) {
  const Args args("render", {"--width", "640", "--pass", "gi", "--quiet"}, specs(), "");
  EXPECT_EQ(args.integer("width", 1, 16384, 320), 640);
  EXPECT_EQ(args.choice("pass", {"full", "gi"}, "full"), "gi");
  EXPECT_TRUE(args.has("quiet"));
  const Args bad("render", {"--width", "0"}, specs(), "");
  EXPECT_THROW((void)bad.integer("width", 1, 16384, 320), engine::core::UsageError);
  EXPECT_THROW(Args("render", {"--height", "5"}, specs(), ""), engine::core::UsageError);
}

TEST(Args, AReadThatDisagreesWithItsDeclarationIsAProgrammingError) {
  const Args args("render", {"--width", "640"}, specs(), "");
  EXPECT_THROW((void)args.integer("width", 1, 4096, 320), std::logic_error);     // another range
  EXPECT_THROW((void)args.choice("pass", {"full", "direct"}, "full"), std::logic_error);  // other choices
  EXPECT_THROW((void)args.str("height", std::string("1")), std::logic_error);   // not declared
  // Without declarations (the older commands) any read is taken as it comes.
  const Args plain("bake", {"--width", "640"}, {"width"});
  EXPECT_EQ(plain.integer("width", 1, 4096, 320), 640);
}

}  // namespace
