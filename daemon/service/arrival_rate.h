#pragma once

#include <array>
#include <chrono>
#include <cstddef>

namespace everytouch::service {

// Events per second over the last `window`: (n - 1) / (newest - oldest) for the n arrivals inside it.
// Unbiased by jitter (a late frame followed by a quick one counts as two frames, not as one long interval),
// and it falls to 0 when the arrivals stop. Keeps the last kCapacity arrivals in a fixed ring.
class ArrivalRate {
public:
    using Clock = std::chrono::steady_clock;
    static constexpr std::size_t kCapacity = 256;

    explicit ArrivalRate(Clock::duration window = std::chrono::seconds(1)) : window_(window) {}

    void add(Clock::time_point arrival);
    // The rate seen from `now`: 0 with fewer than two arrivals in the window.
    double perSecond(Clock::time_point now) const;

private:
    Clock::duration window_;
    std::array<Clock::time_point, kCapacity> arrivals_{};
    std::size_t next_ = 0;
    std::size_t count_ = 0;
};

}  // namespace everytouch::service
