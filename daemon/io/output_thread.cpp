#include "io/output_thread.h"

#include <utility>

#include "io/thread_name.h"

namespace everytouch::io {

OpenedOutput startOutputThread(std::thread& thread, const char* name,
                               std::function<void(std::promise<OpenedOutput>&)> body) {
    std::promise<OpenedOutput> opened;
    std::future<OpenedOutput> result = opened.get_future();
    thread = std::thread([name, &opened, body = std::move(body)] {
        nameThisThread(name);
        body(opened);
    });
    try {
        return result.get();
    } catch (...) {
        thread.join();
        throw;
    }
}

}  // namespace everytouch::io
