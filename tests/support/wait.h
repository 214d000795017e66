#pragma once

#include <chrono>
#include <functional>
#include <thread>

namespace everytouch::test {

// Polls `condition` every 10 ms until it holds or `timeout` passes; whether it held.
inline bool waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
        if (std::chrono::steady_clock::now() > deadline)
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
}

}  // namespace everytouch::test
