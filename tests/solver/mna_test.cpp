#include "solver/mna.h"

#include <gtest/gtest.h>

namespace isolink {
namespace {

TEST(MnaPattern, DeclaredEntriesGetDistinctSlotsAndGroundTheTrash) {
  MnaPattern p(3);
  p.declare(1, 2);
  p.declare(3, 1);
  p.declare(0, 2);  // ground row: not stored
  p.finalize();
  // diagonal (3) + (1,2) + (3,1)
  EXPECT_EQ(p.nonzeros(), 5);
  EXPECT_EQ(p.value_count(), 6);
  EXPECT_EQ(p.slot(0, 2), p.trash());
  EXPECT_EQ(p.slot(2, 0), p.trash());
  // CSC: column 0 (unknown 1) holds rows 0 and 2.
  EXPECT_EQ(p.col_start(), (std::vector<int>{0, 2, 4, 5}));
  EXPECT_EQ(p.row_index(), (std::vector<int>{0, 2, 0, 1, 2}));
  EXPECT_EQ(p.slot(1, 2), 2);
  EXPECT_EQ(p.slot(3, 1), 1);
  EXPECT_EQ(p.slot(3, 3), 4);
}

}  // namespace
}  // namespace isolink
