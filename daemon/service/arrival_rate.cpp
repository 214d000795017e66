#include "service/arrival_rate.h"

namespace everytouch::service {

void ArrivalRate::add(Clock::time_point arrival) {
    arrivals_[next_] = arrival;
    next_ = (next_ + 1) % kCapacity;
    if (count_ < kCapacity)
        ++count_;
}

double ArrivalRate::perSecond(Clock::time_point now) const {
    std::size_t inWindow = 0;
    Clock::time_point oldest, newest;
    // Newest first, until an arrival falls out of the window.
    for (std::size_t i = 1; i <= count_; ++i) {
        const Clock::time_point arrival = arrivals_[(next_ + kCapacity - i) % kCapacity];
        if (now - arrival > window_)
            break;
        if (inWindow == 0)
            newest = arrival;
        oldest = arrival;
        ++inWindow;
    }
    if (inWindow < 2 || newest <= oldest)
        return 0.0;
    return static_cast<double>(inWindow - 1) / std::chrono::duration<double>(newest - oldest).count();
}

}  // namespace everytouch::service
