#include "io/calibration_file.h"

#include <regex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.h"
#include "support/file_contents.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::io {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

class CalibrationFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        writeCalibrationFile(good_, test::paperLikeCalibration());
        goodText_ = test::fileContents(good_);
    }

    // Writes the good file with `pattern` replaced by `replacement` and returns the reader's complaint.
    std::string complaintAfter(const std::string& pattern, const std::string& replacement) {
        const std::string bad = std::regex_replace(goodText_, std::regex(pattern), replacement,
                                                   std::regex_constants::format_first_only);
        EXPECT_NE(bad, goodText_) << "pattern " << pattern << " did not match";
        test::writeText(badPath_, bad);
        try {
            readCalibrationFile(badPath_);
        } catch (const InputError& error) {
            return error.what();
        }
        ADD_FAILURE() << "accepted a file with " << pattern << " -> " << replacement;
        return {};
    }

    test::TempDir dir_;
    std::filesystem::path good_ = dir_ / "calibration.yml";
    std::filesystem::path badPath_ = dir_ / "bad.yml";
    std::string goodText_;
};

TEST_F(CalibrationFileTest, RoundTripKeepsEveryValue) {
    const core::Calibration original = test::paperLikeCalibration();
    const core::Calibration read = readCalibrationFile(good_);
    EXPECT_EQ(read.cameraSize, original.cameraSize);
    EXPECT_EQ(read.projectorSize, original.projectorSize);
    EXPECT_EQ(read.displaySize, original.displaySize);
    EXPECT_TRUE(read.cameraMatrix.isApprox(original.cameraMatrix, 1e-15));
    EXPECT_TRUE(read.projectorMatrix.isApprox(original.projectorMatrix, 1e-15));
    EXPECT_TRUE(read.tableToCamera.matrix().isApprox(original.tableToCamera.matrix(), 1e-15));
    EXPECT_TRUE(read.tableToProjector.matrix().isApprox(original.tableToProjector.matrix(), 1e-15));
    EXPECT_TRUE(read.displayToProjector.isApprox(original.displayToProjector, 1e-15));
    EXPECT_EQ(read.cameraDistortion, original.cameraDistortion);
}

TEST_F(CalibrationFileTest, FileStartsWithFormatAndVersion) {
    EXPECT_THAT(goodText_, HasSubstr("format: everytouch-calibration"));
    EXPECT_THAT(goodText_, HasSubstr("version: 1"));
}

TEST_F(CalibrationFileTest, RejectsMissingKey) {
    EXPECT_THAT(complaintAfter("projector_matrix:", "projector_matrx:"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("projector_matrix"), HasSubstr("missing")));
}

TEST_F(CalibrationFileTest, RejectsWrongMatrixSize) {
    EXPECT_THAT(complaintAfter("(camera_matrix: !!opencv-matrix\\s+rows: )3", "$012"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("camera_matrix")));
}

TEST_F(CalibrationFileTest, RejectsNonFiniteNumber) {
    EXPECT_THAT(complaintAfter("(table_to_camera: !!opencv-matrix[^\\[]+\\[\\s*)[-0-9.e+]+", "$01.nan"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("table_to_camera"), HasSubstr("finite")));
}

TEST_F(CalibrationFileTest, RejectsWrongVersion) {
    EXPECT_THAT(complaintAfter("version: 1", "version: 2"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("version")));
}

TEST_F(CalibrationFileTest, RejectsWrongFormat) {
    EXPECT_THAT(complaintAfter("format: everytouch-calibration", "format: something-else"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("format")));
}

TEST_F(CalibrationFileTest, RejectsSizeThatIsNotTwoPositiveIntegers) {
    EXPECT_THAT(complaintAfter("camera_size: \\[ 648, 488 \\]", "camera_size: [ 648 ]"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("camera_size")));
    EXPECT_THAT(complaintAfter("display_size: \\[ 1280, 960 \\]", "display_size: [ 1280, -960 ]"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("display_size")));
}

TEST_F(CalibrationFileTest, RejectsTransformThatIsNotRigid) {
    EXPECT_THAT(complaintAfter("(table_to_projector: !!opencv-matrix[^\\[]+\\[\\s*)[-0-9.e+]+", "$012.5"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("table_to_projector"), HasSubstr("rotation")));
}

TEST_F(CalibrationFileTest, RejectsTruncatedFile) {
    test::writeText(badPath_, goodText_.substr(0, goodText_.size() / 2));
    EXPECT_THROW(readCalibrationFile(badPath_), InputError);
}

TEST_F(CalibrationFileTest, ReadsAFileUpToAMebibyteAndRefusesALargerOne) {
    // A calibration padded with a comment, read in pieces to its last byte.
    const std::size_t mebibyte = std::size_t{1} << 20;
    const std::string padded = goodText_ + "# " + std::string(mebibyte - goodText_.size() - 3, 'x') + "\n";
    ASSERT_EQ(padded.size(), mebibyte);
    test::writeText(badPath_, padded);
    EXPECT_EQ(readCalibrationFile(badPath_).cameraSize, readCalibrationFile(good_).cameraSize);
    test::writeText(badPath_, padded + "\n");
    EXPECT_THAT([&] { readCalibrationFile(badPath_); },
                ::testing::ThrowsMessage<InputError>(AllOf(HasSubstr("bad.yml"), HasSubstr("1 MiB"))));
}

TEST_F(CalibrationFileTest, RejectsGarbageAndMissingFile) {
    test::writeText(badPath_, "{{{ this is : not [ yaml");
    EXPECT_THROW(readCalibrationFile(badPath_), InputError);
    EXPECT_THAT([&] { readCalibrationFile(dir_ / "nowhere.yml"); },
                ::testing::ThrowsMessage<InputError>(HasSubstr("nowhere.yml")));
}

TEST_F(CalibrationFileTest, RejectsAMatrixThatClaimsMoreThanItHolds) {
    // OpenCV would allocate what rows and cols claim before reading the data (found by fuzzing).
    EXPECT_THAT(
        complaintAfter("(camera_matrix: !!opencv-matrix\\s+rows: )3(\\s+cols: )3", "$011000000$021000000"),
        AllOf(HasSubstr("bad.yml"), HasSubstr("camera_matrix"), HasSubstr("opencv-matrix")));
    // Fewer numbers than rows x cols.
    EXPECT_THAT(complaintAfter("(camera_matrix: !!opencv-matrix\\s+rows: )3", "$014"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("camera_matrix")));
}

TEST_F(CalibrationFileTest, RejectsAnEmptyKeyBeforeOpenCVSeesIt) {
    // OpenCV 4.6 ends the whole process on these (found by fuzzing): they must be an error like any other.
    EXPECT_THAT(complaintAfter("camera_size: \\[ 648, 488 \\]", "camera_size: { : 648 }"),
                AllOf(HasSubstr("bad.yml"), HasSubstr("line 5"), HasSubstr("key without a name")));
    test::writeText(badPath_, "%YAML:1.0\n---\na: 0\n   :\n");
    EXPECT_THAT([&] { readCalibrationFile(badPath_); },
                ::testing::ThrowsMessage<InputError>(AllOf(HasSubstr("bad.yml"), HasSubstr("line 4"))));
}

TEST_F(CalibrationFileTest, RejectsTextAfterTheDocumentMarker) {
    // OpenCV 4.6 loops for ever on this one (found by fuzzing).
    test::writeText(badPath_, "%YAML:1.0\n---a: 0\n~---\nt");
    EXPECT_THAT([&] { readCalibrationFile(badPath_); },
                ::testing::ThrowsMessage<InputError>(AllOf(HasSubstr("bad.yml"), HasSubstr("line 2"))));
}

TEST_F(CalibrationFileTest, RejectsAnIndentedFirstKey) {
    // And on this one (found by fuzzing): the document's keys start at the line's beginning.
    test::writeText(badPath_, "%YAML:1.0\n---\n a: xd-\na_--\n");
    EXPECT_THAT([&] { readCalibrationFile(badPath_); },
                ::testing::ThrowsMessage<InputError>(AllOf(HasSubstr("bad.yml"), HasSubstr("line 3"))));
}

TEST_F(CalibrationFileTest, FailedWriteLeavesTheOldFileIntact) {
    core::Calibration broken = test::paperLikeCalibration();
    broken.cameraMatrix(1, 1) = 0;
    EXPECT_THROW(writeCalibrationFile(good_, broken), InputError);
    EXPECT_EQ(test::fileContents(good_), goodText_);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_.path()), {}), 1)
        << "a temporary file was left";
}

}  // namespace
}  // namespace everytouch::io
