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

}  // namespace
}  // namespace geomip::codec
