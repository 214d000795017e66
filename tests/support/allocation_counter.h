#pragma once

#include <cstdint>

namespace everytouch::test {

// Heap allocations made through operator new (and so by every standard container) by the calling thread so
// far. Linking this in replaces the global operator new with one that counts, which is why it is no part of
// the tests' support library: only the binaries that count allocations compile it. Compare two readings
// around the code under test. Per thread, because library threads (a thread pool, a logger) allocate when
// they will; code under test that hands work to other threads must be made to keep it (cv::setNumThreads(1)).
std::uint64_t allocationCount();

}  // namespace everytouch::test
