#include "io/touch_log.h"

#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/input_error.h"
#include "support/temp_dir.h"

namespace everytouch::io {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::vector<std::string> lines(const std::filesystem::path& path) {
    std::ifstream input(path);
    std::vector<std::string> result;
    for (std::string line; std::getline(input, line);)
        result.push_back(line);
    return result;
}

TEST(TouchLog, WritesOnlyFramesWhereSomethingChanged) {
    test::TempDir dir;
    const core::Contact finger{3, 120.5, 88.2, true, 0.0, false};
    {
        TouchLogWriter writer(dir / "log.jsonl");
        writer.publish(0, 0, {});
        writer.publish(1, 8333, {finger});
        writer.publish(2, 16666, {finger});
        writer.publish(3, 25000, {});
        writer.publish(4, 33333, {});
    }
    const auto written = lines(dir / "log.jsonl");
    ASSERT_EQ(written.size(), 2u);
    EXPECT_EQ(
        nlohmann::json::parse(written[0]),
        nlohmann::json::parse(R"({"index": 1, "t_us": 8333, "contacts": [{"id": 3, "x": 120.5, "y": 88.2,
                                        "touch": true, "height_mm": 0.0}]})"));
    EXPECT_EQ(nlohmann::json::parse(written[1]),
              nlohmann::json::parse(R"({"index": 3, "t_us": 25000, "contacts": []})"));
}

TEST(TouchLog, RoundTripKeepsHoverHeights) {
    test::TempDir dir;
    const core::Contacts contacts{{1, 10.25, 20.5, true, 0.0, false}, {2, 300, 400.75, false, 12.5, false}};
    {
        TouchLogWriter writer(dir / "log.jsonl");
        writer.publish(5, 41665, contacts);
    }
    const auto entries = readTouchLog(dir / "log.jsonl");
    ASSERT_EQ(entries.size(), 1u);
    EXPECT_EQ(entries[0].index, 5u);
    EXPECT_EQ(entries[0].timestampUs, 41665);
    EXPECT_EQ(entries[0].contacts, contacts);
}

TEST(TouchLog, ReaderRejectsBadLinesNamingThem) {
    test::TempDir dir;
    const auto complaint = [&](const std::string& text) -> std::string {
        std::ofstream(dir / "bad.jsonl") << R"({"index": 1, "t_us": 0, "contacts": []})"
                                         << "\n"
                                         << text << "\n";
        try {
            readTouchLog(dir / "bad.jsonl");
        } catch (const InputError& error) {
            return error.what();
        }
        ADD_FAILURE() << "accepted " << text;
        return {};
    };
    EXPECT_THAT(
        complaint(R"({"index": 2, "t_us": 1, "contacts": [{"id": 1, "x": 1, "y": 2, "touch": true}]})"),
        AllOf(HasSubstr("bad.jsonl"), HasSubstr("line 2"), HasSubstr("height_mm")));
    EXPECT_THAT(
        complaint(R"({"index": 2, "t_us": 1, "contacts": [{"id": 1, "x": "a", "y": 2, "touch": true,)"),
        AllOf(HasSubstr("line 2"), HasSubstr("JSON")));
    // An index going back is refused; the same index again is the release logged at the stream's end.
    EXPECT_THAT(complaint(R"({"index": 0, "t_us": 1, "contacts": []})"),
                AllOf(HasSubstr("line 2"), HasSubstr("index")));
    std::ofstream(dir / "release.jsonl") << R"({"index": 1, "t_us": 0, "contacts": []})"
                                         << "\n"
                                         << R"({"index": 1, "t_us": 0, "contacts": []})"
                                         << "\n";
    EXPECT_NO_THROW(readTouchLog(dir / "release.jsonl"));
    EXPECT_THAT(complaint(R"({"index": 2, "t_us": 1, "contacts": {}})"), HasSubstr("contacts"));
    EXPECT_THAT(complaint(R"({"index": -2, "t_us": 1, "contacts": []})"), HasSubstr("index"));
}

}  // namespace
}  // namespace everytouch::io
