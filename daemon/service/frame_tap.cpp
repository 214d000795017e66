#include "service/frame_tap.h"

#include <algorithm>

namespace everytouch::service {

namespace {

core::FramePair deepCopy(const core::FramePair& pair) {
    core::FramePair copy = pair;
    copy.positive.image = pair.positive.image.clone();
    copy.negative.image = pair.negative.image.clone();
    return copy;
}

std::shared_ptr<const core::PipelineResult> deepCopy(const core::PipelineResult& result) {
    auto copy = std::make_shared<core::PipelineResult>();
    copy->frameIndex = result.frameIndex;
    copy->timestampUs = result.timestampUs;
    copy->detecting = result.detecting;
    copy->idleReason = result.idleReason;
    copy->subtraction = result.subtraction.clone();
    copy->texture = result.texture.clone();
    copy->handMask = result.handMask.clone();
    copy->fingertips = result.fingertips;
    copy->contacts = result.contacts;
    return copy;
}

}  // namespace

FrameTap::Ticket FrameTap::request(std::size_t pairs, Done done, bool withDetection) {
    std::lock_guard lock(mutex_);
    const Ticket ticket = nextTicket_++;
    pending_[ticket] = Pending{pairs, withDetection, {}, std::move(done)};
    wanted_ = true;
    return ticket;
}

void FrameTap::cancel(Ticket ticket) {
    std::unique_lock lock(mutex_);
    pending_.erase(ticket);
    wanted_ = !pending_.empty();
    if (deliveringThread_ == std::this_thread::get_id())
        return;
    delivered_.wait(
        lock, [&] { return std::find(delivering_.begin(), delivering_.end(), ticket) == delivering_.end(); });
}

void FrameTap::offer(const core::FramePair& pair, const core::PipelineResult* detection) {
    if (!wanted_.load(std::memory_order_relaxed))
        return;
    std::vector<Pending> filled;
    {
        std::lock_guard lock(mutex_);
        const core::FramePair pairCopy = deepCopy(pair);
        std::shared_ptr<const core::PipelineResult> detectionCopy;
        for (auto it = pending_.begin(); it != pending_.end();) {
            if (it->second.withDetection && detection && !detectionCopy)
                detectionCopy = deepCopy(*detection);
            it->second.pairs.push_back(
                TappedPair{pairCopy, it->second.withDetection ? detectionCopy : nullptr});
            if (it->second.pairs.size() < it->second.wanted) {
                ++it;
                continue;
            }
            delivering_.push_back(it->first);
            filled.push_back(std::move(it->second));
            it = pending_.erase(it);
        }
        wanted_ = !pending_.empty();
        if (!filled.empty())
            deliveringThread_ = std::this_thread::get_id();
    }
    if (filled.empty())
        return;
    for (Pending& request : filled)
        request.done(std::move(request.pairs));
    {
        std::lock_guard lock(mutex_);
        delivering_.clear();
        deliveringThread_ = {};
    }
    delivered_.notify_all();
}

}  // namespace everytouch::service
