// base/csv.h: fields quoted exactly when RFC 4180 needs it, and read back unchanged.
#include "base/csv.h"

#include <gtest/gtest.h>

namespace isolink {
namespace {

TEST(Csv, QuotesOnlyTheFieldsThatNeedIt) {
  EXPECT_EQ(csv_field("time"), "time");
  EXPECT_EQ(csv_field("1.5e-09"), "1.5e-09");
  EXPECT_EQ(csv_field(""), "");
  EXPECT_EQ(csv_field("v(rxp,rxn)"), "\"v(rxp,rxn)\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_field("cr\r"), "\"cr\r\"");
  EXPECT_EQ(csv_field(" padded"), "\" padded\"");
  EXPECT_EQ(csv_field("down v(rxp)"), "down v(rxp)");  // inner spaces need no quotes
}

TEST(Csv, RowJoinsAndEndsWithLf) {
  EXPECT_EQ(csv_row({"time", "down v(rxp,rxn)", "x"}), "time,\"down v(rxp,rxn)\",x\n");
  EXPECT_EQ(csv_row({}), "\n");
}

TEST(Csv, SplitUndoesTheQuoting) {
  const std::vector<std::string> fields = {"a", "v(rxp,rxn)", "", "say \"hi\"", " x "};
  std::string line = csv_row(fields);
  line.pop_back();  // the LF
  EXPECT_EQ(split_csv_line(line), fields);
  EXPECT_EQ(split_csv_line("a,\"b,c\",,\"d\"\"e\""),
            (std::vector<std::string>{"a", "b,c", "", "d\"e"}));
  EXPECT_EQ(split_csv_line("x,y\r"), (std::vector<std::string>{"x", "y"}));
}

}  // namespace
}  // namespace isolink
