#pragma once

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

// Starts `thread`, named `name`, running `body`, which opens the output on that thread, fulfils the promise
// (or sets the exception it failed with) and then runs until told to stop. Returns what it opened; when the
// opening failed, joins the thread and throws that exception.
OpenedOutput startOutputThread(std::thread& thread, const char* name,
                               std::function<void(std::promise<OpenedOutput>&)> body);

}  // namespace everytouch::io
