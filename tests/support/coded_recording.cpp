#include "support/coded_recording.h"

#include <opencv2/core.hpp>

#include "io/recording.h"
#include "support/test_rig.h"

namespace everytouch::test {

io::RigDescription smallRig() {
    io::RigDescription rig = paperLikeRig();
    rig.calibration.cameraSize = {162, 122};
    rig.calibration.cameraMatrix.topRows(2) *= 0.25;
    return rig;
}

CodedImages codedImages(const cv::Size& size, int delta, unsigned seed) {
    cv::Mat bits(size, CV_8UC1);
    cv::RNG rng(seed);
    rng.fill(bits, cv::RNG::UNIFORM, 0, 2);
    // A table lit from one side: a gentle gradient under the code.
    cv::Mat table(size, CV_8UC1);
    for (int y = 0; y < size.height; ++y)
        table.row(y).setTo(100 + 60 * y / size.height);
    CodedImages images;
    images.positive = table + bits * delta;
    images.negative = table - bits * delta;
    return images;
}

void writeCodedRecording(const std::filesystem::path& directory, const io::RigDescription& rig,
                         std::uint64_t frames, std::int64_t intervalUs) {
    const CodedImages images = codedImages(rig.calibration.cameraSize, rig.delta);
    io::RecordingWriter writer(directory, rig, false);
    for (std::uint64_t i = 0; i < frames; ++i) {
        core::Frame frame;
        frame.index = i;
        frame.timestampUs = static_cast<std::int64_t>(i) * intervalUs;
        frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
        frame.image = i % 2 ? images.negative : images.positive;
        writer.addFrame(frame);
    }
    writer.flush();
}

}  // namespace everytouch::test
