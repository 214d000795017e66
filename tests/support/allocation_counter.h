#pragma once

#include <cstdint>

namespace everytouch::test {

// Heap allocations made through operator new (and so by every standard container) by the whole program so
// far. Linking this in replaces the global operator new with one that counts; compare two readings around the
// code under test.
std::uint64_t allocationCount();

}  // namespace everytouch::test
