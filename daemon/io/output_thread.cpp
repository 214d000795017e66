#include "io/output_thread.h"

#include <stdexcept>
#include <utility>

#include "io/log.h"
#include "io/thread_name.h"

namespace everytouch::io {

OpenedOutput OutputThread::start(const char* name, std::function<void(std::promise<OpenedOutput>&)> body) {
    if (thread_.joinable())
        throw std::logic_error("an output's thread is started once");
    std::promise<OpenedOutput> opened;
    std::future<OpenedOutput> result = opened.get_future();
    thread_ = std::thread([name, &opened, body = std::move(body)] {
        nameThisThread(name);
        body(opened);
    });
    try {
        OpenedOutput output = result.get();
        description_ = output.description;
        return output;
    } catch (...) {
        thread_.join();
        throw;
    }
}

OutputThread::~OutputThread() {
    stopping_ = true;
    if (!thread_.joinable())
        return;
    thread_.join();
    if (missed_ > 0)
        ET_LOG(Notice) << description_ << ": " << missed_ << " of " << presented_ + missed_
                       << " refreshes passed without a new image";
}

}  // namespace everytouch::io
