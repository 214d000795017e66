#pragma once

#include "io/projector_output.h"
#include "io/sim_source.h"

namespace everytouch::io {

// The simulated rig's projector as an output: what it shows, the simulated camera sees from the next frame
// on, and the simulated desktop is drawn through the keystone it is given, as a real output draws it.
class SimProjector final : public ProjectorOutput {
public:
    // `source` must outlive the output.
    explicit SimProjector(SimSource& source) : source_(source) {}

    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) override {
        source_.setDisplayToProjector(displaySize, displayToProjector);
    }
    void show(const cv::Mat& projectorImage) override { source_.projectImage(projectorImage); }
    void release() noexcept override { source_.projectImage(cv::Mat()); }
    cv::Size size() const override { return source_.projectorSize(); }
    std::string describe() const override { return "the simulated projector"; }

private:
    SimSource& source_;
};

}  // namespace everytouch::io
