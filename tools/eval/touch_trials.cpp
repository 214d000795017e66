#include "eval/touch_trials.h"

#include <algorithm>
#include <map>
#include <unordered_map>

namespace everytouch::eval {

TruthFrames truthFrames(const io::Recording& recording) {
    std::unordered_map<std::uint64_t, std::size_t> positionOf;
    for (std::size_t position = 0; position < recording.frames().size(); ++position)
        positionOf.emplace(recording.frames()[position].index, position);
    TruthFrames frames(recording.frames().size());
    for (const core::FingerTruth& finger : recording.truth())
        if (const auto found = positionOf.find(finger.frameIndex); found != positionOf.end())
            frames[found->second].push_back(finger);
    return frames;
}

const core::FingerTruth* findFinger(const std::vector<core::FingerTruth>& frame, std::uint32_t finger) {
    const auto found = std::find_if(frame.begin(), frame.end(),
                                    [&](const core::FingerTruth& truth) { return truth.id == finger; });
    return found == frame.end() ? nullptr : &*found;
}

std::vector<TouchTrial> touchTrials(const TruthFrames& truth) {
    std::vector<TouchTrial> trials;
    std::map<std::uint32_t, TouchTrial> open;  // by finger: the trial running up to the last frame
    for (std::size_t position = 0; position < truth.size(); ++position) {
        for (const core::FingerTruth& finger : truth[position]) {
            if (finger.heightMm != 0.0)
                continue;
            const auto running = open.find(finger.id);
            if (running != open.end() && running->second.last + 1 == position)
                running->second.last = position;
            else {
                if (running != open.end())
                    trials.push_back(running->second);
                open[finger.id] = TouchTrial{finger.id, position, position};
            }
        }
    }
    for (const auto& [finger, trial] : open)
        trials.push_back(trial);
    std::sort(trials.begin(), trials.end(), [](const TouchTrial& a, const TouchTrial& b) {
        return a.first != b.first ? a.first < b.first : a.finger < b.finger;
    });
    return trials;
}

}  // namespace everytouch::eval
