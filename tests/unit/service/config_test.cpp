#include "service/config.h"

#include <cstdint>
#include <fstream>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.h"
#include "support/temp_dir.h"

namespace everytouch::service {
namespace {

using ::testing::HasSubstr;

void write(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path) << text;
}

std::string loadError(const std::filesystem::path& path) {
    try {
        loadConfig(path, true);
    } catch (const io::InputError& error) {
        return error.what();
    }
    return "no error";
}

TEST(Config, MissingDefaultFileGivesDefaults) {
    test::TempDir dir;
    EXPECT_EQ(loadConfig(dir / "everytouchd.conf", false), DaemonConfig());
}

TEST(Config, MissingRequiredFileIsNamed) {
    test::TempDir dir;
    EXPECT_THAT(loadError(dir / "absent.conf"), HasSubstr("absent.conf: no such file"));
}

TEST(Config, ReadsEveryKey) {
    test::TempDir dir;
    write(dir / "everytouchd.conf",
          "# comment\n[Camera]\nRig=replay:/srv/rec\n\n[Touch]\nHeightMm = 7.5\n[Output]\nUinput=no\n"
          "[Calibration]\nPath=/var/lib/et/"
          "cal.yml\nCorrect=no\n[Camera]\nPixelFormat=BayerGR8\nFrameRate=119.5\n"
          "ExposureUs=4000\nGainDb=6\nRegion=640x480+16+8\nTrigger=Line1\n"
          "[Projector]\nOutput=external\nSeed=18446744073709551615\nDelta=12\n");
    const DaemonConfig config = loadConfig(dir / "everytouchd.conf", true);
    EXPECT_EQ(config.rig, "replay:/srv/rec");
    EXPECT_EQ(config.camera, (io::CameraSettings{io::CameraPixels::BayerGr8, 119.5, 4000.0, 6.0,
                                                 cv::Rect(16, 8, 640, 480), "Line1"}));
    EXPECT_DOUBLE_EQ(config.touchHeightMm, 7.5);
    EXPECT_EQ(config.uinput, false);
    EXPECT_EQ(config.calibrationPath, "/var/lib/et/cal.yml");
    EXPECT_FALSE(config.correctCalibration);
    EXPECT_TRUE(DaemonConfig().correctCalibration);
    EXPECT_EQ(config.projector, (ProjectorConfig{ProjectorOutput::External,
                                                 std::numeric_limits<std::uint64_t>::max(), 12, ""}));

    write(dir / "everytouchd.conf", "[Projector]\nOutput=window\nDisplay=HDMI-1\n");
    EXPECT_EQ(loadConfig(dir / "everytouchd.conf", true).projector,
              (ProjectorConfig{ProjectorOutput::Window, 1, 10, "HDMI-1"}));
    write(dir / "everytouchd.conf", "[Projector]\nOutput=overlay\nDisplay=DP-2\n");
    EXPECT_EQ(loadConfig(dir / "everytouchd.conf", true).projector,
              (ProjectorConfig{ProjectorOutput::Overlay, 1, 10, "DP-2"}));
}

TEST(Config, DropInsOverrideInLexicalOrderAndEmptyRestoresDefault) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Touch]\nHeightMm=5\n[Camera]\nRig=aravis\nFrameRate=60\n");
    write(dir / "everytouchd.conf.d" / "20-late.conf", "[Touch]\nHeightMm=9\n");
    write(dir / "everytouchd.conf.d" / "10-early.conf", "[Touch]\nHeightMm=1\n[Camera]\nRig=\nFrameRate=\n");
    write(dir / "everytouchd.conf.d" / "ignored.txt", "this is not a config file");
    const DaemonConfig config = loadConfig(dir / "everytouchd.conf", true);
    EXPECT_DOUBLE_EQ(config.touchHeightMm, 9.0);
    EXPECT_EQ(config.rig, "");
    EXPECT_EQ(config.camera.frameRate, std::nullopt);
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Touch]\n\nHeight=3\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("everytouchd.conf:3: [Touch] Height: unknown key; [Touch] knows HeightMm="));
}

TEST(Config, UnknownSectionIsNamed) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Camera]\nRig=sim\n[Display]\nWidth=3\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("everytouchd.conf:4: [Display] Width: unknown section [Display]"));
}

TEST(Config, KeyOutsideASectionIsAnError) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "Rig=sim\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("everytouchd.conf:1: Rig: not inside a [Section]"));
}

TEST(Config, BadValuesSayWhatIsAccepted) {
    test::TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"[Touch]\nHeightMm=three\n",
         ":2: [Touch] HeightMm: expected a number of millimetres, found \"three\""},
        {"[Touch]\nHeightMm=31\n", ":2: [Touch] HeightMm: must be from 0 to 30 mm, found 31"},
        {"[Touch]\nHeightMm=-0.5\n", ":2: [Touch] HeightMm: must be from 0 to 30 mm"},
        {"[Touch]\nHeightMm=nan\n", ":2: [Touch] HeightMm: expected a number"},
        {"[Output]\nUinput=maybe\n", ":2: [Output] Uinput: expected yes or no, found \"maybe\""},
        {"[Calibration]\nPath=calibration.yml\n", ":2: [Calibration] Path: expected an absolute path"},
        {"[Calibration]\nCorrect=sometimes\n",
         ":2: [Calibration] Correct: expected yes or no, found \"sometimes\""},
        {"[Camera]\nRig=webcam\n", ":2: [Camera] Rig: expected sim[:SCENARIO]"},
        {"[Camera]\nPixelFormat=YUV422\n",
         ":2: [Camera] PixelFormat: expected one of Mono8, RGB8, BGR8, BayerRG8, BayerBG8, BayerGR8, "
         "BayerGB8, "
         "found \"YUV422\""},
        {"[Camera]\nFrameRate=0.5\n", ":2: [Camera] FrameRate: must be from 1 to 1000 frames/s, found 0.5"},
        {"[Camera]\nExposureUs=fast\n", ":2: [Camera] ExposureUs: expected a number of microseconds"},
        {"[Camera]\nGainDb=-3\n", ":2: [Camera] GainDb: must be from 0 to 60 dB, found -3"},
        {"[Camera]\nRegion=640x480+8\n",
         ":2: [Camera] Region: expected WIDTHxHEIGHT or WIDTHxHEIGHT+X+Y in pixels, found \"640x480+8\""},
        {"[Camera]\nRegion=32x480\n",
         ":2: [Camera] Region: must be at least 64 pixels wide and high, found 32x480"},
        {"[Camera]\nTrigger=Line 0\n",
         ":2: [Camera] Trigger: expected off or a trigger source such as Line0"},
        {"[Projector]\nOutput=dlp\n",
         ":2: [Projector] Output: expected none, external, window or overlay, found \"dlp\""},
        {"[Projector]\nSeed=-1\n", ":2: [Projector] Seed: expected a whole number from 0 to"},
        {"[Projector]\nSeed=18446744073709551616\n", ":2: [Projector] Seed: expected a whole number"},
        {"[Projector]\nDelta=0\n",
         ":2: [Projector] Delta: expected a whole number of levels from 1 to 127, found \"0\""},
        {"[Projector]\nDelta=128\n", ":2: [Projector] Delta: expected a whole number of levels"},
        {"[Projector]\nDelta=9.5\n", ":2: [Projector] Delta: expected a whole number of levels"},
    };
    for (const auto& [text, expected] : cases) {
        write(dir / "everytouchd.conf", text);
        EXPECT_THAT(loadError(dir / "everytouchd.conf"), HasSubstr(expected)) << text;
    }
}

TEST(Config, MalformedLineIsNamedByLine) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Touch]\nHeightMm=2\n[Camera\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("everytouchd.conf:3: expected [Section], Key=value, a comment or an empty line"));
}

TEST(Config, TheFirstProblemIsReported) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Touch]\nnonsense line\nHeight=3\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"), HasSubstr("everytouchd.conf:2: expected [Section]"));
    write(dir / "everytouchd.conf", "[Touch]\nHeight=3\nnonsense line\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("everytouchd.conf:2: [Touch] Height: unknown key"));
}

TEST(Config, OverlongLineIsAnError) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Calibration]\nPath=/" + std::string(400, 'a') + "\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"), HasSubstr("everytouchd.conf:2: line longer than"));
}

TEST(Config, ProblemInADropInNamesTheDropIn) {
    test::TempDir dir;
    write(dir / "everytouchd.conf", "[Touch]\nHeightMm=5\n");
    write(dir / "everytouchd.conf.d" / "50-site.conf", "[Touch]\n# fine so far\nHeightMm=50\n");
    EXPECT_THAT(loadError(dir / "everytouchd.conf"),
                HasSubstr("50-site.conf:3: [Touch] HeightMm: must be from"));
}

}  // namespace
}  // namespace everytouch::service
