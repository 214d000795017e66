#include "accuracy_rig.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::calib {
namespace {

using ::testing::HasSubstr;

std::string problemOf(const std::string& rig) {
    const auto found = accuracyTestRig(rig);
    const auto* problem = std::get_if<std::string>(&found);
    return problem ? *problem : std::string();
}

TEST(AccuracyTestRig, TheSimulatedGrid35SessionShowsAndTapsTheCircles) {
    EXPECT_EQ(accuracyTestRig("sim:grid35"),
              (std::variant<AccuracyTestRig, std::string>(AccuracyTestRig::SimulatedSession)));
    EXPECT_EQ(accuracyTestRig("sim:grid35,seed=3,surface=yellow,light=dark"),
              (std::variant<AccuracyTestRig, std::string>(AccuracyTestRig::SimulatedSession)));
}

TEST(AccuracyTestRig, ACameraRigsProjectorShowsTheCirclesForAPersonToTap) {
    for (const char* rig : {"aravis", "aravis:Basler-1", "v4l2:/dev/video0"})
        EXPECT_EQ(accuracyTestRig(rig), (std::variant<AccuracyTestRig, std::string>(AccuracyTestRig::Camera)))
            << rig;
}

TEST(AccuracyTestRig, OtherSimulatedScenariosAreNamedWithTheWayToRunTheTest) {
    for (const char* rig : {"sim", "sim:demo", "sim:drag,seed=2", "sim:seed=1"}) {
        const std::string problem = problemOf(rig);
        EXPECT_THAT(problem, HasSubstr(std::string("the simulated rig ") + rig)) << rig;
        EXPECT_THAT(problem, HasSubstr("does not tap the accuracy test's circles")) << rig;
        EXPECT_THAT(problem, HasSubstr("everytouchd --rig sim:grid35")) << rig;
    }
}

TEST(AccuracyTestRig, ARecordingTapsNoCircleTheTestCouldShow) {
    const std::string problem = problemOf("replay:/tmp/grid35");
    EXPECT_THAT(problem, HasSubstr("everytouchd replays replay:/tmp/grid35"));
    EXPECT_THAT(problem, HasSubstr("on a camera rig"));
    EXPECT_THAT(problemOf("webcam"), HasSubstr("a rig this tool does not know"));
}

}  // namespace
}  // namespace everytouch::calib
