#pragma once

#include <pthread.h>

namespace everytouch::io {

// Names the calling thread as top -H, ps -L and gdb show it: "et-" and what it does, 15 characters at most.
inline void nameThisThread(const char* name) {
    pthread_setname_np(pthread_self(), name);
}

}  // namespace everytouch::io
