#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <string>
#include <thread>

#include <opencv2/core/types.hpp>

namespace everytouch::io {

// What a projector output's thread opened: the panel and the output in words.
struct OpenedOutput {
    cv::Size size;
    std::string description;
};

// The thread a projector output draws on, and the refreshes it counts. Destroying it stops and joins the
// thread, so an output declares it last: the thread ends before anything it draws from goes away, whether
// the output is destroyed or its constructor throws after start().
class OutputThread {
public:
    OutputThread() = default;
    ~OutputThread();
    OutputThread(const OutputThread&) = delete;
    OutputThread& operator=(const OutputThread&) = delete;

    // Starts the thread, named `name`, running `body`, which opens the output on that thread, fulfils the
    // promise (or sets the exception it failed with) and then draws until stopping() turns true. Returns
    // what it opened; when the opening failed, joins the thread and throws that exception. Once only.
    OpenedOutput start(const char* name, std::function<void(std::promise<OpenedOutput>&)> body);

    bool stopping() const { return stopping_; }

    // Counted by the thread: a refresh that showed an image, and refreshes that passed without a new one
    // (each swaps the polarity the camera sees; the camera's side re-locks on the code's sign). The missed
    // ones are said when the thread stops.
    void countPresented() { ++presented_; }
    void countMissed(std::uint64_t refreshes) { missed_ += refreshes; }
    std::uint64_t presented() const { return presented_; }

private:
    std::atomic<bool> stopping_{false};
    std::atomic<std::uint64_t> presented_{0};
    std::atomic<std::uint64_t> missed_{0};
    std::string description_;
    std::thread thread_;
};

}  // namespace everytouch::io
