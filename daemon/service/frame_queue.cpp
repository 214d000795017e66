#include "service/frame_queue.h"

#include <stdexcept>

namespace everytouch::service {

FrameQueue::FrameQueue(std::size_t capacity, Overflow overflow) : slots_(capacity), overflow_(overflow) {
    if (capacity == 0)
        throw std::invalid_argument("FrameQueue needs at least one slot");
}

bool FrameQueue::push(QueuedFrame&& frame) {
    std::unique_lock lock(mutex_);
    if (overflow_ == Overflow::Block)
        notFull_.wait(lock, [&] { return closed_ || count_ < slots_.size(); });
    if (closed_)
        return false;
    if (count_ == slots_.size()) {
        head_ = (head_ + 1) % slots_.size();
        --count_;
        ++dropped_;
    }
    slots_[(head_ + count_) % slots_.size()] = std::move(frame);
    ++count_;
    lock.unlock();
    notEmpty_.notify_one();
    return true;
}

FrameQueue::PopResult FrameQueue::pop(QueuedFrame& frame, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!notEmpty_.wait_for(lock, timeout, [&] { return closed_ || count_ > 0; }))
        return PopResult::Timeout;
    if (count_ == 0)
        return PopResult::Closed;
    frame = std::move(slots_[head_]);
    head_ = (head_ + 1) % slots_.size();
    --count_;
    lock.unlock();
    notFull_.notify_one();
    return PopResult::Frame;
}

void FrameQueue::close() {
    {
        std::lock_guard lock(mutex_);
        closed_ = true;
    }
    notEmpty_.notify_all();
    notFull_.notify_all();
}

std::uint64_t FrameQueue::dropped() const {
    std::lock_guard lock(mutex_);
    return dropped_;
}

}  // namespace everytouch::service
