#include "accuracy_rig.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace everytouch::calib {
namespace {

using ::testing::HasSubstr;

TEST(AccuracyTestRig, TheSimulatedGrid35SessionRunsTheTest) {
    EXPECT_EQ(accuracyTestRigProblem("sim:grid35"), std::nullopt);
    EXPECT_EQ(accuracyTestRigProblem("sim:grid35,seed=3,surface=yellow,light=dark"), std::nullopt);
}

TEST(AccuracyTestRig, OtherSimulatedScenariosAreNamedWithTheWayToRunTheTest) {
    for (const char* rig : {"sim", "sim:demo", "sim:drag,seed=2", "sim:seed=1"}) {
        const std::optional<std::string> problem = accuracyTestRigProblem(rig);
        ASSERT_TRUE(problem.has_value()) << rig;
        EXPECT_THAT(*problem, HasSubstr(std::string("the simulated rig ") + rig)) << rig;
        EXPECT_THAT(*problem, HasSubstr("does not tap the accuracy test's circles")) << rig;
        EXPECT_THAT(*problem, HasSubstr("everytouchd --rig sim:grid35")) << rig;
    }
}

TEST(AccuracyTestRig, RecordingsAndCamerasNeedTheProjectorThisBuildDoesNotDrive) {
    for (const char* rig : {"replay:/tmp/grid35", "aravis", "aravis:Basler-1", "v4l2:/dev/video0"}) {
        const std::optional<std::string> problem = accuracyTestRigProblem(rig);
        ASSERT_TRUE(problem.has_value()) << rig;
        EXPECT_THAT(*problem, HasSubstr(std::string("everytouchd runs on ") + rig)) << rig;
        EXPECT_THAT(*problem, HasSubstr("this build cannot do yet")) << rig;
        EXPECT_THAT(*problem, HasSubstr("everytouchd --rig sim:grid35")) << rig;
    }
    EXPECT_THAT(accuracyTestRigProblem("webcam").value_or(""), HasSubstr("a rig this tool does not know"));
}

}  // namespace
}  // namespace everytouch::calib
