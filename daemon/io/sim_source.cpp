#include "io/sim_source.h"

#include <stdexcept>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "io/input_error.h"
#include "sim/content.h"
#include "sim/sim_options.h"

namespace everytouch::io {

SimSource::SimSource(const RigSpec& spec, bool paced) : spec_(spec.toString()), paced_(paced) {
    const std::string input = "--rig " + spec_;
    sim::SimParameters parameters;
    if (!spec.target.empty())
        parameters.scenario = spec.target;
    for (const auto& [key, value] : spec.options)
        if (auto problem = sim::applyOption(parameters, key, value))
            throw InputError(input, key, *problem);
    if (auto problem = parameters.validate())
        throw InputError(input, "", *problem);
    cv::Mat contentImage;
    if (parameters.content != "auto" && !sim::contentKindFromName(parameters.content)) {
        contentImage = cv::imread(parameters.content, cv::IMREAD_COLOR);
        if (contentImage.empty())
            throw InputError(
                input, "content",
                "\"" + parameters.content +
                    "\" is neither a procedural kind (grid35, shapes, photo, ui, text, white, gray) "
                    "nor a readable image file");
    }
    try {
        simulator_ = std::make_unique<sim::Simulator>(parameters, sim::rigPattern(parameters), contentImage);
        index_ = simulator_->firstFrame();
    } catch (const std::invalid_argument& error) {
        throw InputError(input, "", error.what());
    }
}

bool SimSource::faultAt(std::uint64_t index, std::optional<double> fromS, double forS) const {
    const double seconds = static_cast<double>(index) / simulator_->parameters().frameRate;
    return fromS && seconds >= *fromS && seconds < *fromS + forS;
}

std::optional<core::Frame> SimSource::read(cv::Mat spare) {
    const sim::SimParameters& parameters = simulator_->parameters();
    // The frames of a stall never come; the one after it comes at its own time, and a paced camera is silent
    // for the stall's length even when rendering lags behind real time.
    if (faultAt(index_, parameters.stallS, parameters.stallDurationS)) {
        while (faultAt(index_, parameters.stallS, parameters.stallDurationS))
            ++index_;
        if (paced_) {
            std::this_thread::sleep_for(std::chrono::duration<double>(parameters.stallDurationS));
            start_ = std::chrono::steady_clock::now() -
                     std::chrono::microseconds(simulator_->frameTimestampUs(index_));
        }
    }
    if (const auto end = simulator_->endFrame(); end && index_ >= *end)
        return std::nullopt;
    core::Frame frame;
    frame.image = std::move(spare);
    {
        std::unique_lock lock(renderMutex_);
        othersDone_.wait(lock, [this] { return othersWaiting_ == 0; });
        simulator_->render(index_, frame, truth_);
        truthDisplaySize_ = simulator_->calibration().displaySize;
    }
    if (faultAt(index_, parameters.wrongSizeS, parameters.wrongSizeDurationS)) {
        const cv::Size size = frame.image.size();
        frame.image =
            frame.image(cv::Rect(size.width / 4, size.height / 4, size.width / 2, size.height / 2)).clone();
    }
    truthIndex_ = index_;
    if (paced_) {
        if (!start_)
            start_ = std::chrono::steady_clock::now() - std::chrono::microseconds(frame.timestampUs);
        std::this_thread::sleep_until(*start_ + std::chrono::microseconds(frame.timestampUs));
    }
    ++index_;
    return frame;
}

std::unique_lock<std::mutex> SimSource::betweenFrames() const {
    ++othersWaiting_;
    std::unique_lock lock(renderMutex_);
    --othersWaiting_;
    othersDone_.notify_all();
    return lock;
}

void SimSource::projectImage(const cv::Mat& projectorImage) {
    const std::unique_lock lock = betweenFrames();
    simulator_->projectImage(projectorImage);
}

void SimSource::setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    const std::unique_lock lock = betweenFrames();
    simulator_->setDisplayToProjector(displaySize, displayToProjector);
}

std::optional<RigDescription> SimSource::rig() const {
    RigDescription description;
    {
        const std::unique_lock lock = betweenFrames();
        description.calibration = simulator_->calibration();
    }
    description.delta = simulator_->parameters().delta;
    description.frameRate = simulator_->parameters().frameRate;
    description.pattern = simulator_->pattern().clone();
    return description;
}

std::string SimSource::describe() const {
    return "simulated rig " + spec_;
}

std::optional<std::vector<core::FingerTruth>> SimSource::truth() const {
    std::vector<core::FingerTruth> fingers;
    const cv::Size display = truthDisplaySize_;
    for (const sim::FingertipTruth& tip : truth_.fingertips)
        if (tip.presented && tip.display.x >= 0.0 && tip.display.y >= 0.0 && tip.display.x < display.width &&
            tip.display.y < display.height)
            fingers.push_back({truthIndex_, tip.id, tip.display.x, tip.display.y, tip.heightMm});
    return fingers;
}

}  // namespace everytouch::io
