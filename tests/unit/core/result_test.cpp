#include "core/result.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;

Result<int> half(int value) {
    if (value % 2 != 0)
        return Failure{"value: " + std::to_string(value) + " is odd"};
    return value / 2;
}

Status even(int value) {
    if (value % 2 != 0)
        return Failure{"value: " + std::to_string(value) + " is odd"};
    return {};
}

// Reads the message a logic_error carries, or "" when `body` does not throw one.
template <typename Body>
std::string logicError(Body&& body) {
    try {
        body();
    } catch (const std::logic_error& error) {
        return error.what();
    }
    return "";
}

TEST(Result, HoldsTheValue) {
    const Result<int> result = half(8);
    ASSERT_TRUE(result.ok());
    EXPECT_EQ(result.value(), 4);
}

TEST(Result, HoldsTheFailure) {
    const Result<int> result = half(7);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.failure().message, "value: 7 is odd");
}

TEST(Result, ReadingTheMissingSideIsAProgrammingError) {
    const Result<int> failed = half(7);
    EXPECT_THAT(logicError([&] { (void)failed.value(); }), HasSubstr("value: 7 is odd"));
    EXPECT_THAT(logicError([&] { (void)failed.operator->(); }), HasSubstr("value: 7 is odd"));
    const Result<int> succeeded = half(8);
    EXPECT_THAT(logicError([&] { (void)succeeded.failure(); }), HasSubstr("holds a value"));
}

TEST(Result, GivesAccessToTheValuesMembersAndMovesItOut) {
    Result<std::vector<int>> numbers = std::vector<int>{1, 2, 3};
    EXPECT_EQ(numbers->size(), 3u);
    numbers.value().push_back(4);
    const std::vector<int> taken = std::move(numbers).value();
    EXPECT_EQ(taken, (std::vector<int>{1, 2, 3, 4}));

    Result<std::unique_ptr<int>> owned = std::make_unique<int>(5);
    const std::unique_ptr<int> moved = std::move(owned).value();
    ASSERT_TRUE(moved);
    EXPECT_EQ(*moved, 5);
}

TEST(Status, IsASuccessOrTheFailure) {
    EXPECT_TRUE(even(2).ok());
    const Status odd = even(3);
    ASSERT_FALSE(odd.ok());
    EXPECT_EQ(odd.failure().message, "value: 3 is odd");
    EXPECT_THAT(logicError([] { (void)even(2).failure(); }), HasSubstr("of a success"));
}

}  // namespace
}  // namespace everytouch::core
