// The built-in part library, loaded once per test binary (a failed load fails the test that
// asked for it and leaves an empty library).
#pragma once

#include <gtest/gtest.h>

#include "netlists/link/parts.h"

namespace isolink::testing {

inline const link::PartLibrary& builtin() {
  static const link::PartLibrary lib = [] {
    StatusOr<link::PartLibrary> l = link::PartLibrary::load({});
    EXPECT_TRUE(l.ok()) << l.status().message();
    return l.ok() ? *l : link::PartLibrary{};
  }();
  return lib;
}

}  // namespace isolink::testing
