#include "eval/source_run.h"

#include "core/frame_pairer.h"
#include "io/input_error.h"

namespace everytouch::eval {

SourceRun runOnSource(io::FrameSource& source, const std::string& name, std::size_t maxFrames,
                      const core::DetectionOptions& options, double touchHeightMm) {
    SourceRun run;
    const std::optional<io::RigDescription> rig = source.rig();
    if (!rig)
        throw io::InputError(name, "", "describes no rig (calibration and projected code) to detect with");
    run.rig = *rig;
    core::TouchPipeline pipeline(options);
    const core::PipelineSettings settings{run.rig.calibration, run.rig.pattern, touchHeightMm};
    core::FramePairer pairer;
    while (maxFrames == 0 || run.truth.size() < maxFrames) {
        std::optional<core::Frame> frame = source.next();
        if (!frame)
            break;
        std::optional<std::vector<core::FingerTruth>> truth = source.truth();
        if (!truth)
            throw io::InputError(name, "", "has no ground truth to score against");
        run.truth.push_back(std::move(*truth));
        run.detected.push_back(run.detected.empty() ? core::Contacts{} : run.detected.back());
        if (const std::optional<core::FramePair> pair = pairer.push(std::move(*frame)))
            run.detected.back() = pipeline.process(*pair, settings).contacts;
    }
    return run;
}

}  // namespace everytouch::eval
