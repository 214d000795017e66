#include "service/frame_tap.h"

namespace everytouch::service {

namespace {

core::FramePair deepCopy(const core::FramePair& pair) {
    core::FramePair copy = pair;
    copy.positive.image = pair.positive.image.clone();
    copy.negative.image = pair.negative.image.clone();
    return copy;
}

}  // namespace

FrameTap::Ticket FrameTap::request(std::size_t pairs, Done done) {
    std::lock_guard lock(mutex_);
    const Ticket ticket = nextTicket_++;
    pending_[ticket] = Pending{pairs, {}, std::move(done)};
    wanted_ = true;
    return ticket;
}

void FrameTap::cancel(Ticket ticket) {
    std::lock_guard lock(mutex_);
    pending_.erase(ticket);
    wanted_ = !pending_.empty();
}

void FrameTap::offer(const core::FramePair& pair) {
    if (!wanted_.load(std::memory_order_relaxed))
        return;
    std::vector<Pending> filled;
    {
        std::lock_guard lock(mutex_);
        const core::FramePair copy = deepCopy(pair);
        for (auto it = pending_.begin(); it != pending_.end();) {
            it->second.pairs.push_back(copy);
            if (it->second.pairs.size() < it->second.wanted) {
                ++it;
                continue;
            }
            filled.push_back(std::move(it->second));
            it = pending_.erase(it);
        }
        wanted_ = !pending_.empty();
    }
    for (Pending& request : filled)
        request.done(std::move(request.pairs));
}

}  // namespace everytouch::service
