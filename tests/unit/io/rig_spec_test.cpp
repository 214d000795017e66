#include "io/rig_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.h"

namespace everytouch::io {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Pair;

TEST(RigSpec, SimWithScenarioAndOptions) {
    const RigSpec spec = RigSpec::parse("sim:grid35,seed=3,surface=yellow,light=dark");
    EXPECT_EQ(spec.kind, RigSpec::Kind::Sim);
    EXPECT_EQ(spec.target, "grid35");
    EXPECT_THAT(spec.options,
                ElementsAre(Pair("seed", "3"), Pair("surface", "yellow"), Pair("light", "dark")));
    EXPECT_EQ(spec.toString(), "sim:grid35,seed=3,surface=yellow,light=dark");
}

TEST(RigSpec, SimDefaultsAndOptionsWithoutScenario) {
    EXPECT_EQ(RigSpec::parse("sim").target, "");
    const RigSpec spec = RigSpec::parse("sim:seed=9");
    EXPECT_EQ(spec.target, "");
    EXPECT_THAT(spec.options, ElementsAre(Pair("seed", "9")));
}

TEST(RigSpec, CameraAndReplayKinds) {
    EXPECT_EQ(RigSpec::parse("replay:/tmp/rec").target, "/tmp/rec");
    EXPECT_EQ(RigSpec::parse("aravis").kind, RigSpec::Kind::Aravis);
    EXPECT_EQ(RigSpec::parse("aravis:Fake_1").target, "Fake_1");
    const RigSpec v4l2 = RigSpec::parse("v4l2:/dev/video2");
    EXPECT_EQ(v4l2.kind, RigSpec::Kind::V4l2);
    EXPECT_EQ(v4l2.toString(), "v4l2:/dev/video2");
}

TEST(RigSpec, RejectsMalformedSpecsNamingTheOption) {
    for (const char* bad : {"webcam", "replay", "replay:", "v4l2", "sim:grid35,grid35", "sim:seed=1,seed=2",
                            "sim:=3", "sim:a,,b"}) {
        EXPECT_THAT([&] { RigSpec::parse(bad); }, ::testing::ThrowsMessage<InputError>(HasSubstr("--rig")))
            << bad;
    }
}

}  // namespace
}  // namespace everytouch::io
