#include "io/v4l2_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.h"

// What can be tested without a camera: the source says clearly what it opened instead of one. The capture
// path itself runs against the kernel's vivid driver in the virtual machine
// (tests/vm/v4l2_source_vm_test.cpp).
namespace everytouch::io {
namespace {

using ::testing::HasSubstr;

TEST(V4l2Source, AMissingNodeIsNamedAndMayComeBack) {
    try {
        V4l2Source source("--rig v4l2:/dev/video-none", "/dev/video-none", CameraSettings{});
        FAIL() << "opened a node that does not exist";
    } catch (const InputError&) {
        FAIL() << "a missing node is no bad input: the camera may be plugged in later";
    } catch (const std::runtime_error& error) {
        EXPECT_THAT(error.what(), HasSubstr("--rig v4l2:/dev/video-none: cannot open /dev/video-none"));
        EXPECT_THAT(error.what(), HasSubstr("No such file or directory"));
    }
}

TEST(V4l2Source, ANodeThatIsNoCameraIsBadInput) {
    try {
        V4l2Source source("--rig v4l2:/dev/null", "/dev/null", CameraSettings{});
        FAIL() << "took /dev/null for a camera";
    } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("--rig v4l2:/dev/null: /dev/null is no V4L2 device"));
    }
}

}  // namespace
}  // namespace everytouch::io
