#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace everytouch::service {

// What a full queue does with one more item: a live camera cannot wait, so the oldest item is dropped and
// counted; a recording or the simulator can, and its producer waits for a free slot.
enum class QueueOverflow { DropOldest, Block };
enum class QueuePop { Item, Timeout, Closed };

// Hands items from one thread to another through a fixed ring of slots, whose items are moved in and out:
// once every slot has held an item of full size, nothing is allocated.
template <typename Item>
class BoundedQueue {
public:
    using Overflow = QueueOverflow;
    using PopResult = QueuePop;

    // Throws std::invalid_argument for a capacity of 0.
    BoundedQueue(std::size_t capacity, Overflow overflow) : slots_(capacity), overflow_(overflow) {
        if (capacity == 0)
            throw std::invalid_argument("a bounded queue needs at least one slot");
    }

    // False once the queue is closed (the item is not queued).
    bool push(Item&& item) {
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
        slots_[(head_ + count_) % slots_.size()] = std::move(item);
        ++count_;
        lock.unlock();
        notEmpty_.notify_one();
        return true;
    }

    // Takes the oldest item, waiting up to `timeout`. After close() the items still queued are delivered
    // before Closed is reported.
    PopResult pop(Item& item, std::chrono::milliseconds timeout) {
        std::unique_lock lock(mutex_);
        if (!notEmpty_.wait_for(lock, timeout, [&] { return closed_ || count_ > 0; }))
            return PopResult::Timeout;
        if (count_ == 0)
            return PopResult::Closed;
        item = std::move(slots_[head_]);
        head_ = (head_ + 1) % slots_.size();
        --count_;
        lock.unlock();
        notFull_.notify_one();
        return PopResult::Item;
    }

    // Ends the stream: push fails from now on and waiting producers and consumers wake up.
    void close() {
        {
            std::lock_guard lock(mutex_);
            closed_ = true;
        }
        notEmpty_.notify_all();
        notFull_.notify_all();
    }

    std::uint64_t dropped() const {
        std::lock_guard lock(mutex_);
        return dropped_;
    }

private:
    mutable std::mutex mutex_;
    std::condition_variable notEmpty_;
    std::condition_variable notFull_;
    std::vector<Item> slots_;
    Overflow overflow_;
    std::size_t head_ = 0;  // the oldest item
    std::size_t count_ = 0;
    std::uint64_t dropped_ = 0;
    bool closed_ = false;
};

}  // namespace everytouch::service
