#include "service/frame_pool.h"

#include <atomic>

namespace everytouch::service {

FramePool::FramePool(std::size_t capacity) : capacity_(capacity) {
    spares_.reserve(capacity);
}

cv::Mat FramePool::take() {
    std::lock_guard lock(mutex_);
    if (spares_.empty())
        return {};
    cv::Mat image = std::move(spares_.back());
    spares_.pop_back();
    return image;
}

void FramePool::giveBack(cv::Mat&& image) {
    // The only holder: no other thread can take a reference to it meanwhile. OpenCV counts references
    // atomically; the count is read so too.
    if (image.empty() || image.u == nullptr || !image.isContinuous() ||
        std::atomic_ref<int>(image.u->refcount).load(std::memory_order_acquire) != 1)
        return;
    std::lock_guard lock(mutex_);
    if (spares_.size() < capacity_)
        spares_.push_back(std::move(image));
}

std::size_t FramePool::spares() const {
    std::lock_guard lock(mutex_);
    return spares_.size();
}

}  // namespace everytouch::service
