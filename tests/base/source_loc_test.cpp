// error_at (base/source_loc.h): a place gives "file:line:col: error: message", the line and a
// caret under the column; no place gives the message alone (not "<unknown>: error: ...").
#include "base/source_loc.h"

#include <gtest/gtest.h>

namespace isolink {
namespace {

TEST(SourceLoc, ErrorAtAPlaceHasItsLineAndCaret) {
  SourceLoc loc;
  loc.file = SourceFile::FromText("spec.yaml", "name: x\ncable: {length: -1}\n");
  loc.line = 2, loc.col = 17;
  const Status s = error_at(loc, "cable.length = -1: must be positive");
  EXPECT_EQ(s.message(),
            "spec.yaml:2:17: error: cable.length = -1: must be positive\n"
            " cable: {length: -1}\n"
            "                 ^");
}

TEST(SourceLoc, ErrorAtNoPlaceIsTheMessageAlone) {
  const Status s = error_at(SourceLoc{}, "cable.length = -1: must be positive");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "cable.length = -1: must be positive");
}

}  // namespace
}  // namespace isolink
