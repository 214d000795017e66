#include "eval/source_run.h"

#include "io/input_error.h"

namespace everytouch::eval {

SourceRun runOnSource(io::FrameSource& source, const std::string& name, std::size_t maxFrames,
                      const core::DetectionOptions& options, double touchHeightMm) {
    SourceRun run;
    const std::optional<io::RigDescription> rig = source.rig();
    if (!rig)
        throw io::InputError(name, "", "describes no rig (calibration and projected code) to detect with");
    run.rig = *rig;
    PipelineContacts pipeline(run.rig, options, touchHeightMm);
    while (maxFrames == 0 || run.truth.size() < maxFrames) {
        std::optional<core::Frame> frame = source.next();
        if (!frame)
            break;
        std::optional<std::vector<core::FingerTruth>> truth = source.truth();
        if (!truth)
            throw io::InputError(name, "", "has no ground truth to score against");
        run.truth.push_back(std::move(*truth));
        pipeline.add(*frame, run.detected);
    }
    return run;
}

}  // namespace everytouch::eval
