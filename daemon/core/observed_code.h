#pragma once

#include <bit>
#include <cstdint>

namespace everytouch::core {

// A codeword as the camera saw it: bit i as in the pattern's codewords (core/pattern.h), and which of the
// bits were seen with enough contrast to be trusted. An unknown bit is neither 0 nor 1; it does not count in
// any distance.
struct ObservedCode {
    std::uint64_t bits = 0;   // 1 where the camera saw a 1-bit; 0 elsewhere, including unknown bits
    std::uint64_t known = 0;  // 1 where the bit was read; 0 where it is unknown

    int knownCount() const { return std::popcount(known); }
};

// Hamming distance between an expected codeword and an observed one over the observed code's known bits.
inline int hammingDistance(std::uint64_t expected, const ObservedCode& observed) {
    return std::popcount((expected ^ observed.bits) & observed.known);
}

}  // namespace everytouch::core
