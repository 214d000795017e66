#include "eval/recording_pairs.h"

#include <algorithm>

#include "core/code_image.h"

namespace everytouch::eval {

RecordingPairs::RecordingPairs(const io::Recording& recording, const TruthToCamera& truthToCamera)
    : recording_(recording), truthToCamera_(truthToCamera) {}

bool RecordingPairs::next(PairWithTruth& out) {
    while (nextPosition_ < recording_.frames().size()) {
        const std::size_t position = nextPosition_++;
        if (std::optional<core::FramePair> pair = pairer_.push(recording_.loadFrame(position))) {
            complete(*pair, position, out);
            return true;
        }
    }
    return false;
}

bool RecordingPairs::at(std::size_t position, PairWithTruth& out) const {
    if (position == 0 || position >= recording_.frames().size())
        return false;
    core::FramePairer pairer;
    pairer.push(recording_.loadFrame(position - 1));
    const std::optional<core::FramePair> pair = pairer.push(recording_.loadFrame(position));
    if (!pair)
        return false;
    complete(*pair, position, out);
    return true;
}

void RecordingPairs::complete(const core::FramePair& pair, std::size_t position, PairWithTruth& out) const {
    out.position = position;
    out.pair = pair;
    core::computeSubtractionAndTexture(pair, out.subtraction, out.texture);
    out.truthMask = recording_.loadMask(position);
    out.fingers.clear();
    const std::uint64_t index = recording_.frames()[position].index;
    const std::vector<core::FingerTruth>& truth = recording_.truth();
    auto first = std::lower_bound(
        truth.begin(), truth.end(), index,
        [](const core::FingerTruth& finger, std::uint64_t i) { return finger.frameIndex < i; });
    const cv::Rect frame(cv::Point(0, 0), out.truthMask.size());
    for (auto finger = first; finger != truth.end() && finger->frameIndex == index; ++finger) {
        // A finger over the display but high enough to be out of the camera's view cannot be found.
        const TruthPoint point = truthToCamera_(*finger);
        if (frame.contains(cv::Point2d(point.camera.x(), point.camera.y())))
            out.fingers.push_back(point);
    }
}

}  // namespace everytouch::eval
