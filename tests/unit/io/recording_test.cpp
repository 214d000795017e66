#include "io/recording.h"

#include <sys/resource.h>

#include <csignal>
#include <regex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/input_error.h"
#include "support/file_contents.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::io {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

core::Frame makeFrame(std::uint64_t index, const cv::Size& size) {
    core::Frame frame;
    frame.index = index;
    frame.timestampUs = 1000 + static_cast<std::int64_t>(index) * 8333;
    frame.polarity = index % 2 == 0 ? core::Polarity::Positive : core::Polarity::Negative;
    frame.image.create(size, CV_8UC3);
    cv::randu(frame.image, 0, 256);
    return frame;
}

// A hand-like blob that moves from frame to frame.
cv::Mat makeMask(std::uint64_t index, const cv::Size& size) {
    cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
    cv::ellipse(mask, cv::Point(100 + 40 * static_cast<int>(index), 200), cv::Size(60, 25), 30.0, 0.0, 360.0,
                cv::Scalar(255), cv::FILLED);
    return mask;
}

class RecordingTest : public ::testing::Test {
protected:
    void SetUp() override {
        rig_ = test::paperLikeRig();
        RecordingWriter writer(dir_.path(), rig_, true, true);
        for (std::uint64_t i = 0; i < 4; ++i) {
            frames_.push_back(makeFrame(i, rig_.calibration.cameraSize));
            masks_.push_back(makeMask(i, rig_.calibration.cameraSize));
            writer.addFrame(frames_.back());
            writer.addTruth({{i, 7, 100.5 + i, 200.25, i == 3 ? 0.0 : 4.5}});
            writer.addMask(i, masks_.back());
        }
        writer.flush();
    }

    std::string complaint() {
        try {
            Recording::open(dir_.path());
        } catch (const InputError& error) {
            return error.what();
        }
        ADD_FAILURE() << "the recording was accepted";
        return {};
    }

    // Replaces the first match of `pattern` in the recording's `file`.
    void edit(const std::string& file, const std::string& pattern, const std::string& replacement) {
        const std::string before = test::fileContents(dir_ / file);
        const std::string after = std::regex_replace(before, std::regex(pattern), replacement,
                                                     std::regex_constants::format_first_only);
        ASSERT_NE(before, after) << pattern;
        test::writeText(dir_ / file, after);
    }

    test::TempDir dir_;
    RigDescription rig_;
    std::vector<core::Frame> frames_;
    std::vector<cv::Mat> masks_;
};

// What reading mask number `position` of the recording in `directory` complains about.
std::string maskComplaint(const std::filesystem::path& directory, std::size_t position) {
    const Recording recording = Recording::open(directory);
    try {
        recording.loadMask(position);
    } catch (const InputError& error) {
        return error.what();
    }
    ADD_FAILURE() << "the mask was accepted";
    return {};
}

TEST_F(RecordingTest, RoundTripGivesBackRigFramesAndTruth) {
    const Recording recording = Recording::open(dir_.path());
    EXPECT_EQ(recording.rig().delta, rig_.delta);
    EXPECT_EQ(recording.rig().frameRate, rig_.frameRate);
    EXPECT_EQ(cv::countNonZero(recording.rig().pattern != rig_.pattern), 0);
    EXPECT_TRUE(recording.rig().calibration.cameraMatrix.isApprox(rig_.calibration.cameraMatrix));
    ASSERT_EQ(recording.frames().size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        const core::Frame frame = recording.loadFrame(i);
        EXPECT_EQ(frame.index, frames_[i].index);
        EXPECT_EQ(frame.timestampUs, frames_[i].timestampUs);
        EXPECT_EQ(frame.polarity, frames_[i].polarity);
        EXPECT_EQ(cv::norm(frame.image, frames_[i].image, cv::NORM_INF), 0.0) << "frames must be lossless";
    }
    ASSERT_TRUE(recording.hasTruth());
    ASSERT_EQ(recording.truth().size(), 4u);
    EXPECT_EQ(recording.truth()[1], (core::FingerTruth{1, 7, 101.5, 200.25, 4.5}));
    EXPECT_EQ(recording.truth()[3].heightMm, 0.0);
    ASSERT_TRUE(recording.hasMasks());
    for (std::size_t i = 0; i < 4; ++i) {
        const cv::Mat mask = recording.loadMask(i);
        EXPECT_EQ(mask.type(), CV_8UC1);
        EXPECT_EQ(cv::norm(mask, masks_[i], cv::NORM_INF), 0.0) << "masks must be lossless";
    }
    EXPECT_TRUE(std::filesystem::is_regular_file(dir_ / "masks" / "000003.png"));
}

TEST_F(RecordingTest, RecordingWithoutMasksOpens) {
    std::filesystem::remove_all(dir_ / "masks");
    const Recording recording = Recording::open(dir_.path());
    EXPECT_FALSE(recording.hasMasks());
    EXPECT_EQ(recording.frames().size(), 4u);
    EXPECT_THROW(recording.loadMask(0), std::logic_error);
}

TEST_F(RecordingTest, WriterWithoutMasksWritesNoMasksDirectory) {
    test::TempDir other;
    RecordingWriter writer(other / "rec", rig_, false);
    writer.addFrame(frames_[0]);
    EXPECT_THROW(writer.addMask(0, masks_[0]), std::logic_error);
    writer.flush();
    EXPECT_FALSE(std::filesystem::exists(other / "rec" / "masks"));
    EXPECT_FALSE(Recording::open(other / "rec").hasMasks());
}

TEST_F(RecordingTest, WriterRefusesAMaskOfAnotherSizeOrTypeAndTakesItsFrameBack) {
    for (const cv::Mat& refused : {cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)),
                                   cv::Mat(rig_.calibration.cameraSize, CV_8UC3, cv::Scalar::all(0))}) {
        test::TempDir other;
        RecordingWriter writer(other / "rec", rig_, false, true);
        writer.addFrame(frames_[0]);
        writer.addMask(0, cv::Mat(rig_.calibration.cameraSize, CV_8UC1, cv::Scalar(0)));
        writer.addFrame(frames_[1]);
        EXPECT_THROW(writer.addMask(frames_[1].index, refused), std::invalid_argument);
        // The writer stops, keeping the frames before whole: the refused mask's frame goes with it.
        EXPECT_TRUE(writer.stopped());
        const Recording recorded = Recording::open(other / "rec");
        ASSERT_EQ(recorded.frames().size(), 1u);
        EXPECT_EQ(recorded.frames()[0].index, frames_[0].index);
    }
}

TEST_F(RecordingTest, RejectsMissingMaskFile) {
    std::filesystem::remove(Recording::maskPath(dir_.path(), 2));
    EXPECT_THAT(complaint(), AllOf(HasSubstr("masks/000002.png"), HasSubstr("missing")));
}

TEST_F(RecordingTest, RejectsMasksThatAreNotADirectory) {
    std::filesystem::remove_all(dir_ / "masks");
    test::writeText(dir_ / "masks", "not a directory\n");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("masks"), HasSubstr("directory")));
}

TEST_F(RecordingTest, MaskOfWrongSizeIsRejectedWhenRead) {
    cv::imwrite(Recording::maskPath(dir_.path(), 1).string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)));
    EXPECT_THAT(
        maskComplaint(dir_.path(), 1),
        AllOf(HasSubstr("masks/000001.png"), HasSubstr("camera size 648x488"), HasSubstr("found 10x10")));
}

TEST_F(RecordingTest, MaskOfWrongTypeIsRejectedWhenRead) {
    cv::Mat wide;
    masks_[1].convertTo(wide, CV_16UC1);
    ASSERT_TRUE(cv::imwrite(Recording::maskPath(dir_.path(), 1).string(), wide));
    EXPECT_THAT(maskComplaint(dir_.path(), 1),
                AllOf(HasSubstr("masks/000001.png"), HasSubstr("8-bit single-channel"), HasSubstr("16-bit")));
    cv::Mat colour;
    cv::cvtColor(masks_[2], colour, cv::COLOR_GRAY2BGR);
    ASSERT_TRUE(cv::imwrite(Recording::maskPath(dir_.path(), 2).string(), colour));
    EXPECT_THAT(
        maskComplaint(dir_.path(), 2),
        AllOf(HasSubstr("masks/000002.png"), HasSubstr("8-bit single-channel"), HasSubstr("3 channels")));
}

TEST_F(RecordingTest, MaskWithValuesOtherThan0And255IsRejectedWhenRead) {
    cv::Mat blurred;
    cv::GaussianBlur(masks_[3], blurred, cv::Size(5, 5), 0.0);
    ASSERT_TRUE(cv::imwrite(Recording::maskPath(dir_.path(), 3).string(), blurred));
    EXPECT_THAT(maskComplaint(dir_.path(), 3),
                AllOf(HasSubstr("masks/000003.png"), HasSubstr("only the values 0 and 255")));
}

TEST_F(RecordingTest, UnreadableMaskIsRejectedWhenRead) {
    test::writeText(Recording::maskPath(dir_.path(), 0), "not a png");
    EXPECT_THAT(maskComplaint(dir_.path(), 0),
                AllOf(HasSubstr("masks/000000.png"), HasSubstr("not a readable")));
}

TEST_F(RecordingTest, PatternFileUses0And255) {
    const cv::Mat pattern = cv::imread((dir_ / "pattern.png").string(), cv::IMREAD_UNCHANGED);
    EXPECT_EQ(pattern.type(), CV_8UC1);
    EXPECT_EQ(cv::countNonZero(pattern == 0) + cv::countNonZero(pattern == 255),
              static_cast<int>(pattern.total()));
}

TEST_F(RecordingTest, WriterRefusesANonEmptyDirectory) {
    EXPECT_THROW(RecordingWriter(dir_.path(), rig_, false), InputError);
}

TEST_F(RecordingTest, RejectsPolarityOtherThanPlusOrMinusOne) {
    edit("frames.csv", ",-1\n", ",0\n");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("frames.csv"), HasSubstr("line 3"), HasSubstr("polarity")));
}

TEST_F(RecordingTest, RejectsMissingFrameFile) {
    std::filesystem::remove(Recording::framePath(dir_.path(), 2));
    EXPECT_THAT(complaint(), AllOf(HasSubstr("000002.png"), HasSubstr("missing")));
}

TEST_F(RecordingTest, RejectsTruncatedFramesLine) {
    const std::string text = test::fileContents(dir_ / "frames.csv");
    test::writeText(dir_ / "frames.csv", text.substr(0, text.size() - 4));
    EXPECT_THAT(complaint(), AllOf(HasSubstr("frames.csv"), HasSubstr("line 5")));
}

TEST_F(RecordingTest, RejectsTruncatedTruthLine) {
    edit("truth.csv", "\n2,7,[^\n]*\n", "\n2,7,102.5\n");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("truth.csv"), HasSubstr("line 4"), HasSubstr("truncated")));
}

TEST_F(RecordingTest, RejectsNegativeOrNonFiniteTruth) {
    edit("truth.csv", "4\\.500\n", "-1\n");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("truth.csv"), HasSubstr("height_mm")));
    edit("truth.csv", "-1\n", "nan\n");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("truth.csv"), HasSubstr("height_mm")));
}

TEST_F(RecordingTest, RejectsWrongHeader) {
    edit("frames.csv", "timestamp_us", "time");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("frames.csv"), HasSubstr("header")));
}

TEST_F(RecordingTest, RejectsMissingRigKey) {
    edit("rig.yml", "delta:", "deltas:");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("rig.yml"), HasSubstr("delta"), HasSubstr("missing")));
}

TEST_F(RecordingTest, RejectsWrongVersion) {
    edit("rig.yml", "version: 1", "version: 7");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("rig.yml"), HasSubstr("version")));
}

TEST_F(RecordingTest, RejectsBadCalibrationInRig) {
    edit("rig.yml", "(projector_matrix: !!opencv-matrix\\s+rows: 3\\s+cols: )3", "$012");
    EXPECT_THAT(complaint(), AllOf(HasSubstr("rig.yml"), HasSubstr("projector_matrix")));
}

TEST_F(RecordingTest, APatternNameTheSystemRefusesIsNamedNotThrownAsAFilesystemError) {
    // Found by fuzzing: one component longer than any file name may be.
    const std::string tooLong(300, 'p');
    edit("rig.yml", "pattern: \"pattern.png\"", "pattern: \"" + tooLong + ".png\"");
    EXPECT_THAT(complaint(), AllOf(HasSubstr(tooLong), HasSubstr("cannot be accessed")));
}

TEST_F(RecordingTest, RejectsPatternOfWrongSizeOrValues) {
    cv::imwrite((dir_ / "pattern.png").string(), cv::Mat(100, 100, CV_8UC1, cv::Scalar(255)));
    EXPECT_THAT(complaint(), AllOf(HasSubstr("pattern.png"), HasSubstr("projector size")));
    cv::imwrite((dir_ / "pattern.png").string(),
                cv::Mat(rig_.calibration.projectorSize, CV_8UC1, cv::Scalar(128)));
    EXPECT_THAT(complaint(), AllOf(HasSubstr("pattern.png"), HasSubstr("0 and 255")));
}

TEST_F(RecordingTest, FrameOfWrongSizeIsRejectedWhenRead) {
    cv::imwrite(Recording::framePath(dir_.path(), 1).string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)));
    const Recording recording = Recording::open(dir_.path());
    EXPECT_THAT([&] { recording.loadFrame(1); },
                ::testing::ThrowsMessage<InputError>(HasSubstr("000001.png")));
}

// A PNG's first 24 bytes: the signature and an IHDR chunk declaring `width` x `height`, 8-bit gray; no
// pixels.
std::string pngHeader(std::uint32_t width, std::uint32_t height) {
    std::string header("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
    for (std::uint32_t value : {width, height})
        for (int shift = 24; shift >= 0; shift -= 8)
            header += static_cast<char>((value >> shift) & 0xff);
    return header + std::string("\x08\0\0\0\0\0\0\0\0", 9);
}

TEST_F(RecordingTest, AnImageWhoseHeaderClaimsAnotherSizeIsRefusedBeforeItIsDecoded) {
    // 40000 x 40000 would be 1.6 GB to allocate before the first pixel.
    test::writeText(Recording::framePath(dir_.path(), 1), pngHeader(40000, 40000));
    test::writeText(Recording::maskPath(dir_.path(), 2), pngHeader(40000, 40000));
    const Recording recording = Recording::open(dir_.path());
    EXPECT_THAT([&] { recording.loadFrame(1); },
                ::testing::ThrowsMessage<InputError>(AllOf(
                    HasSubstr("frames/000001.png"), HasSubstr("camera size 648x488, found 40000x40000"))));
    EXPECT_THAT(maskComplaint(dir_.path(), 2),
                AllOf(HasSubstr("masks/000002.png"), HasSubstr("found 40000x40000")));
}

TEST_F(RecordingTest, AFrameThatIsNoPngIsRefusedEvenWhenItDecodes) {
    std::vector<uchar> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", frames_[2].image, jpeg));
    test::writeText(Recording::framePath(dir_.path(), 2), std::string(jpeg.begin(), jpeg.end()));
    const Recording recording = Recording::open(dir_.path());
    EXPECT_THAT([&] { recording.loadFrame(2); },
                ::testing::ThrowsMessage<InputError>(
                    AllOf(HasSubstr("frames/000002.png"), HasSubstr("not a readable PNG image"))));
}

// A file size limit makes the writes of one frame fail as a full disk would, in this process and without
// privileges: the frame's image is refused (EFBIG), its truth and mask, written before, are taken back.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        getrlimit(RLIMIT_FSIZE, &saved_);
        previousHandler_ = std::signal(SIGXFSZ, SIG_IGN);
        rlimit limit = saved_;
        limit.rlim_cur = bytes;
        setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &saved_);
        std::signal(SIGXFSZ, previousHandler_);
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;

private:
    rlimit saved_{};
    void (*previousHandler_)(int) = SIG_DFL;
};

TEST(RecordingWriterTest, AWriteThatFailsTakesItsFrameBackAndKeepsEveryFrameBefore) {
    const test::TempDir dir;
    const RigDescription rig = test::paperLikeRig();
    const cv::Size size = rig.calibration.cameraSize;
    RecordingWriter writer(dir / "rec", rig, true, true);
    for (std::uint64_t i = 0; i < 4; ++i) {
        core::Frame frame = makeFrame(i, size);
        // Flat frames make small files; the fourth is noise, larger than the limit below.
        if (i < 3)
            frame.image.setTo(cv::Scalar(90, 120, 150));
        writer.addTruth({{i, 1, 10.0 + i, 20.0, 1.5}});
        writer.addMask(i, makeMask(i, size));
        if (i < 3) {
            writer.addFrame(frame);
            continue;
        }
        const FileSizeLimit limit(64 * 1024);
        try {
            writer.addFrame(frame);
            FAIL() << "a frame larger than the file size limit was written";
        } catch (const std::system_error& error) {
            EXPECT_THAT(error.what(), HasSubstr("frames/000003.png"));
            EXPECT_THAT(error.what(), HasSubstr("File too large"));
        }
    }
    EXPECT_EQ(writer.framesWritten(), 3u);
    EXPECT_THROW(writer.addFrame(makeFrame(4, size)), std::logic_error);
    writer.flush();

    const Recording recording = Recording::open(dir / "rec");
    ASSERT_EQ(recording.frames().size(), 3u);
    EXPECT_EQ(recording.frames().back().index, 2u);
    ASSERT_EQ(recording.truth().size(), 3u);
    EXPECT_EQ(recording.truth().back().frameIndex, 2u);
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(cv::norm(recording.loadFrame(i).image, cv::Mat(size, CV_8UC3, cv::Scalar(90, 120, 150)),
                           cv::NORM_INF),
                  0.0);
        EXPECT_EQ(cv::norm(recording.loadMask(i), makeMask(i, size), cv::NORM_INF), 0.0);
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "rec" / "masks" / "000003.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "rec" / "frames" / "000003.png"));
}

}  // namespace
}  // namespace everytouch::io
