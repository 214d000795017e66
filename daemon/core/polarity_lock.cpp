#include "core/polarity_lock.h"

#include <cmath>

namespace everytouch::core {

void PolarityLock::setRig(const TableCode& tableCode, const cv::Mat& region) {
    CV_Assert(tableCode.predicted.type() == CV_32FC1 && region.type() == CV_8UC1 &&
              region.size() == tableCode.predicted.size());
    runs_.clear();
    predicted_.clear();
    predictedSquares_ = 0.0;
    for (int y = 0; y < region.rows; y += kRowStep) {
        const uchar* inside = region.ptr<uchar>(y);
        const float* code = tableCode.predicted.ptr<float>(y);
        for (int x = 0; x + kRunPx <= region.cols; x += kRunPx) {
            bool usable = true;
            float mean = 0.0f;
            for (int k = 0; k < kRunPx && usable; ++k) {
                usable = inside[x + k] != 0 && code[x + k] >= 0.0f;
                mean += code[x + k] / kRunPx;
            }
            if (!usable)
                continue;
            runs_.push_back({y, x});
            for (int k = 0; k < kRunPx; ++k) {
                predicted_.push_back(code[x + k] - mean);
                predictedSquares_ += double(code[x + k] - mean) * (code[x + k] - mean);
            }
        }
    }
    // Neighbouring pixels share light through the camera's blur: about two pixels per independent sample.
    const double pixels = static_cast<double>(predicted_.size());
    chance_ = pixels > 0 ? std::sqrt(2.0 / pixels) : 1.0;
    correlation_ = 0.0;
}

bool PolarityLock::relock(const cv::Mat& subtraction) {
    CV_Assert(subtraction.type() == CV_16SC1);
    correlation_ = 0.0;
    if (runs_.empty() || predictedSquares_ <= 0.0)
        return false;
    double cross = 0.0, squares = 0.0;
    const float* predicted = predicted_.data();
    for (const Run& run : runs_) {
        const short* s = subtraction.ptr<short>(run.y) + run.x;
        int sum = 0;
        for (int k = 0; k < kRunPx; ++k)
            sum += s[k];
        const float mean = static_cast<float>(sum) / kRunPx;
        float runCross = 0.0f, runSquares = 0.0f;
        for (int k = 0; k < kRunPx; ++k) {
            const float value = static_cast<float>(s[k]) - mean;
            runCross += value * predicted[k];
            runSquares += value * value;
        }
        cross += runCross;
        squares += runSquares;
        predicted += kRunPx;
    }
    if (squares <= 0.0)
        return false;
    correlation_ = cross / std::sqrt(squares * predictedSquares_);
    if (correlation_ >= -kSignificance * chance_)
        return false;
    swapped_ = !swapped_;
    ++swaps_;
    return true;
}

FramePair swappedPair(const FramePair& pair) {
    FramePair swapped{pair.negative, pair.positive};
    swapped.positive.polarity = Polarity::Positive;
    swapped.negative.polarity = Polarity::Negative;
    return swapped;
}

}  // namespace everytouch::core
