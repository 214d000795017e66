#include "io/sim_source.h"

#include <stdexcept>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "io/input_error.h"
#include "sim/content.h"
#include "sim/sim_options.h"

namespace everytouch::io {

namespace {

// The projected code: a random binary pattern of the projector's size, fixed by the seed.
cv::Mat randomPattern(cv::Size size, std::uint64_t seed) {
    cv::Mat pattern(size, CV_8UC1);
    cv::RNG rng(seed);
    rng.fill(pattern, cv::RNG::UNIFORM, 0, 2);
    return pattern;
}

}  // namespace

SimSource::SimSource(const RigSpec& spec, bool paced) : spec_(spec.toString()), paced_(paced) {
    const std::string input = "--rig " + spec_;
    sim::SimParameters parameters;
    if (!spec.target.empty())
        parameters.scenario = spec.target;
    for (const auto& [key, value] : spec.options)
        if (auto problem = sim::applyOption(parameters, key, value))
            throw InputError(input, key, *problem);
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
        simulator_ = std::make_unique<sim::Simulator>(
            parameters, randomPattern(parameters.projectorSize, parameters.seed), contentImage);
    } catch (const std::invalid_argument& error) {
        throw InputError(input, "", error.what());
    }
}

std::optional<core::Frame> SimSource::next() {
    if (const auto count = simulator_->frameCount(); count && index_ >= *count)
        return std::nullopt;
    core::Frame frame;
    simulator_->render(index_, frame, truth_);
    truthIndex_ = index_;
    if (paced_) {
        if (index_ == 0)
            start_ = std::chrono::steady_clock::now();
        std::this_thread::sleep_until(start_ + std::chrono::microseconds(frame.timestampUs));
    }
    ++index_;
    return frame;
}

std::optional<RigDescription> SimSource::rig() const {
    RigDescription description;
    description.calibration = simulator_->calibration();
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
    for (const sim::FingertipTruth& tip : truth_.fingertips)
        if (tip.presented)
            fingers.push_back({truthIndex_, tip.id, tip.display.x, tip.display.y, tip.heightMm});
    return fingers;
}

}  // namespace everytouch::io
