// Shared helpers of the C++ suites.
#pragma once

#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace graspsim::test_util {

// Runs `fn`, expects an Error with `code` whose message contains every string in `parts`.
template <typename Fn>
void ExpectError(Fn&& fn, ErrorCode code, std::initializer_list<const char*> parts) {
  try {
    fn();
    ADD_FAILURE() << "no error thrown";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), code) << error.what();
    for (const char* part : parts) {
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << "'" << part << "' not in: " << error.what();
    }
  }
}

}  // namespace graspsim::test_util
